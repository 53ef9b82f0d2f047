"""Real-time scheduling from Python: run_scene's rt_priority (issue 33).

A real-time session (a bridged device) asks for SCHED_FIFO at rt_priority, reports what it got
in stats["realtime"] and how late its sleeps woke in stats["wakeup"]; rt_priority=None asks for
nothing; batch runs never ask; a bad priority is a ValueError naming the argument and range.

Where the system permits real time (root, CAP_SYS_NICE or RLIMIT_RTPRIO at the priority), the
grant is asserted; where it does not, the refusal `no_permission`. A machine that permits
SCHED_FIFO but gives it no run time (a container) cannot check the grant: the test fails there
unless NANOHAPTICS_SKIP_REALTIME=1 (README.md, docs/testing.md), and then it is skipped, saying
why.
"""

import os
import resource
import threading
from pathlib import Path

import pytest

import nanohaptics as nh
from nanohaptics import bridge

from test_live import free_port

ROOT = Path(__file__).resolve().parents[2]
WALL = ROOT / "scenes" / "wall.toml"


CAP_SYS_NICE = 23


def rt_permitted(priority):
    """What the engine asks (crates/engine/src/realtime.rs): CAP_SYS_NICE, or RLIMIT_RTPRIO at
    or above the priority."""
    with open("/proc/self/status") as f:
        cap_eff = next(int(line.split()[1], 16) for line in f if line.startswith("CapEff:"))
    if cap_eff >> CAP_SYS_NICE & 1:
        return True
    soft, _ = resource.getrlimit(resource.RLIMIT_RTPRIO)
    return soft == resource.RLIM_INFINITY or soft >= priority


def cannot_run_here(why):
    if os.environ.get("NANOHAPTICS_SKIP_REALTIME") == "1":
        print(f"SKIPPED (NANOHAPTICS_SKIP_REALTIME=1): {why}")
        pytest.skip(f"NANOHAPTICS_SKIP_REALTIME=1: {why}")
    pytest.fail(f"{why}; set NANOHAPTICS_SKIP_REALTIME=1 to skip it on this machine "
                "(README.md, docs/testing.md)")


def bridged(rt_priority):
    port = free_port()
    result = {}

    def sim():
        result.update(nh.run_scene(str(WALL), device=f"udp:127.0.0.1:{port}", wait_s=20.0,
                                   rt_priority=rt_priority))

    t = threading.Thread(target=sim)
    t.start()
    specs = bridge.Specs("falcon", 8.0, 3000.0, 0.04, ["centre", "plus", "minus", "forward"])
    client = bridge.BridgeClient(("127.0.0.1", port), specs, protocol=2)
    try:
        client.connect(20.0)
        for _ in range(100):
            client.send((0.0, 0.0, 0.0))
            client.receive(0.01)
    finally:
        client.close()
    t.join()
    return result["stats"]


def test_batch_runs_never_ask_and_a_bad_priority_names_itself():
    s = nh.run_scene("brickworld", seconds=0.05)["stats"]
    assert s["realtime"]["requested"] is False
    assert s["realtime"]["priority"] is None
    assert s["wakeup"]["max_ns"] == 0
    for bad in (0, 100, -5):
        with pytest.raises(ValueError) as e:
            nh.run_scene("brickworld", seconds=0.05, rt_priority=bad)
        assert str(e.value) == f"rt_priority = {bad} is out of range: allowed 1 to 99"


def test_a_bridged_session_asks_for_real_time_unless_told_not_to():
    off = bridged(None)["realtime"]
    assert off["requested"] is False and off["priority"] is None
    rt = bridged(60)["realtime"]
    assert rt["requested"] is True
    if not rt_permitted(60):
        assert rt["priority"] is None and rt["sched_refused"] == "no_permission", rt
    elif rt["sched_refused"] == "no_runtime":
        cannot_run_here("the system permits SCHED_FIFO here but gives real-time tasks no run "
                        f"time (a container, or a cgroup with cpu.rt_runtime_us 0): {rt}")
    else:
        # Granted: SCHED_FIFO at the priority asked for.
        assert rt["priority"] == 60 and rt["sched_refused"] is None, rt
