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
