"""Shared fixtures of the Python tests."""

import signal
import threading

import pytest


@pytest.fixture
def sigint_raises():
    """SIGINT raises KeyboardInterrupt in the main thread for the test's duration, whatever
    disposition the test process inherited: a parent that ignores SIGINT (``nohup cmd &``,
    a ``trap '' INT`` shell) starts Python with SIG_IGN, and then neither Ctrl-C nor
    ``_thread.interrupt_main()`` raises anything. The inherited disposition is restored
    afterwards."""
    assert threading.current_thread() is threading.main_thread()
    previous = signal.signal(signal.SIGINT, signal.default_int_handler)
    try:
        yield
    finally:
        signal.signal(signal.SIGINT, previous)


# The threads the device adapters of nanohaptics.bridge start (ForceDimensionDevice,
# HaplyInverse3Device); TouchDevice's servo is the SDK's own callback.
ADAPTER_THREADS = ("forcedimension-servo", "inverse3-servo", "inverse3-handle")


@pytest.fixture(autouse=True)
def no_adapter_left_running():
    """Every device a test opens is closed by its end: an adapter's servo thread left running
    goes on taking the interpreter lock every millisecond for the rest of the run (it slowed
    later live sessions, and the garbage collector ran in it). Fails the test that left one
    (after a 1.5 s grace for a close still joining)."""
    before = set(threading.enumerate())
    yield
    left = [t for t in threading.enumerate()
            if t not in before and t.name in ADAPTER_THREADS and t.is_alive()]
    for t in left:
        t.join(timeout=1.5)
    left = [t.name for t in left if t.is_alive()]
    assert not left, f"the test left device threads running: {', '.join(left)} (close the device)"
