"""The `nanohaptics` command the wheel installs (issue 32, item 1): `pip install nanohaptics`
gives the same program as the binary, as a console script and as `python -m nanohaptics`.

Every test runs the installed command as a process, from a scratch folder that holds no
repository files: the built-in scenes and the play page must come from inside the wheel.
What each test expects is what the cargo-built binary does (its Ctrl-C handling included).
"""

from __future__ import annotations

import os
import queue
import re
import signal
import socket
import subprocess
import sys
import sysconfig
import threading
import time
import urllib.request
from importlib.metadata import entry_points
from pathlib import Path

import pytest

import nanohaptics as nh

ROOT = Path(__file__).resolve().parents[2]
# Where pip put the console script: the environment's bin (Scripts on Windows).
COMMAND = Path(sysconfig.get_path("scripts")) / "nanohaptics"
CLI_DOC = ROOT / "crates" / "cli" / "src" / "lib.rs"
PAGE = ROOT / "crates" / "play" / "src" / "page"

pytestmark = pytest.mark.skipif(sys.platform == "win32", reason="POSIX signals and paths")


def nanohaptics(*args: str, cwd: Path, timeout: float = 120) -> subprocess.CompletedProcess:
    return subprocess.run(
        [str(COMMAND), *args], cwd=cwd, capture_output=True, text=True, timeout=timeout
    )


def commands_in_help(text: str) -> list[str]:
    """The command names of clap's `--help` (the lines under `Commands:`)."""
    section = text.split("\nCommands:\n", 1)[1].split("\n\n", 1)[0]
    return [line.split()[0] for line in section.splitlines() if line.startswith("  ")]


class Lines:
    """A child's text pipe read line by line on a thread, so a test can wait for a line with a
    time limit (select() on the pipe misses lines already in the reader's buffer)."""

    def __init__(self, stream):
        self.queue: queue.Queue[str] = queue.Queue()
        self.thread = threading.Thread(target=self._pump, args=(stream,), daemon=True)
        self.thread.start()

    def _pump(self, stream) -> None:
        for line in stream:
            self.queue.put(line)
        self.queue.put("")  # end of the stream

    def next(self, seconds: float) -> str:
        """The next line, or a failure after `seconds`."""
        try:
            return self.queue.get(timeout=seconds)
        except queue.Empty:
            raise AssertionError(f"no line within {seconds} s") from None

    def rest(self) -> str:
        """Everything after the lines read so far, once the stream has ended."""
        out = []
        while (line := self.queue.get(timeout=30)) != "":
            out.append(line)
        return "".join(out)


def wait_for(path: Path, proc: subprocess.Popen, seconds: float) -> None:
    deadline = time.monotonic() + seconds
    while not path.exists():
        assert proc.poll() is None, proc.communicate()
        assert time.monotonic() < deadline, f"{path.name} did not appear within {seconds} s"
        time.sleep(0.05)


def interrupt(p: subprocess.Popen, seconds: float = 10) -> float:
    """Ctrl-C to `p`; how long it took to end, s (a failure after `seconds`)."""
    sent = time.monotonic()
    p.send_signal(signal.SIGINT)
    p.wait(timeout=seconds)
    return time.monotonic() - sent


def end(p: subprocess.Popen, *readers: Lines) -> None:
    """No child and no open pipe left behind, whatever failed."""
    if p.poll() is None:
        p.kill()
        p.wait()
    for r in readers:
        r.thread.join(timeout=10)
    for stream in (p.stdout, p.stderr):
        if stream is not None:
            stream.close()


@pytest.fixture
def scratch(tmp_path: Path) -> Path:
    """A working folder outside the repository, with no `scenes/` of its own."""
    assert ROOT not in tmp_path.resolve().parents
    assert not (tmp_path / "scenes").exists()
    return tmp_path


def test_the_console_script_is_installed_and_prints_the_version(scratch):
    (ep,) = entry_points(group="console_scripts", name="nanohaptics")
    assert ep.value == "nanohaptics.__main__:main"
    assert COMMAND.is_file() and os.access(COMMAND, os.X_OK), COMMAND
    r = nanohaptics("--version", cwd=scratch)
    assert (r.returncode, r.stdout, r.stderr) == (0, f"nanohaptics {nh.__version__}\n", "")


def test_python_m_nanohaptics_is_the_same_program(scratch):
    script = nanohaptics("--help", cwd=scratch)
    module = subprocess.run(
        [sys.executable, "-m", "nanohaptics", "--help"],
        cwd=scratch,
        capture_output=True,
        text=True,
        timeout=60,
    )
    assert script.returncode == module.returncode == 0, module.stderr
    assert module.stdout == script.stdout
    assert module.stdout.startswith("Deterministic haptic sessions")
    # Every command of the crate's usage block (its own test keeps that block complete).
    usage = re.findall(r"^//! nanohaptics ([a-z-]+) ", CLI_DOC.read_text(encoding="utf-8"), re.M)
    assert {"run", "play", "replay", "demo", "lesson", "render", "fake-device"} <= set(usage)
    assert sorted(commands_in_help(module.stdout)) == sorted({*usage, "help"})


@pytest.mark.parametrize(
    "args",
    [
        ["--help"],
        ["run", "--help"],
        ["play", "--help"],
        ["scenes"],
        ["run", "brickworld", "--seconds", "abc"],
        ["replay", "no-such.mcap", "--verify"],
        [],
    ],
    ids=" ".join,
)
def test_the_command_answers_as_the_binary(scratch, args):
    binary = ROOT / "target" / "release" / "nanohaptics"
    if not binary.is_file():
        pytest.skip("the nanohaptics binary is not built (scripts/test.sh builds it before pytest)")
    ours = nanohaptics(*args, cwd=scratch)
    theirs = subprocess.run([str(binary), *args], cwd=scratch, capture_output=True, text=True, timeout=60)
    assert (ours.returncode, ours.stdout, ours.stderr) == (theirs.returncode, theirs.stdout, theirs.stderr)
    assert (ours.stdout + ours.stderr).strip()


def test_run_and_replay_work_outside_the_repository(scratch):
    r = nanohaptics("run", "brickworld", "--seconds", "0.5", "--out", "rec.mcap", cwd=scratch)
    assert r.returncode == 0, r.stderr
    assert r.stdout.startswith("brick world: build a small wall (batch, ")
    assert "  500 ticks (0.500 s)" in r.stdout
    assert (scratch / "rec.mcap").is_file()
    v = nanohaptics("replay", "rec.mcap", "--verify", cwd=scratch)
    assert v.returncode == 0, v.stderr
    assert re.match(r"rec\.mcap: 500 ticks replayed, \d+ output messages identical bit for bit\n", v.stdout)
    # The recording the command wrote is the module's too.
    assert nh.read_recording(scratch / "rec.mcap")["tick"].shape == (500,)


def test_a_bad_argument_is_claps_usage_error(scratch):
    r = nanohaptics("run", "brickworld", "--no-such-flag", cwd=scratch)
    assert r.returncode == 2 and r.stdout == ""
    lines = r.stderr.splitlines()
    assert lines[0] == "error: unexpected argument '--no-such-flag' found"
    assert "Usage: nanohaptics run <SCENE>" in lines
    assert lines[-1] == "For more information, try '--help'."


def test_a_bad_scene_is_status_1_with_its_error(scratch):
    listed = nanohaptics("scenes", cwd=scratch)
    assert listed.returncode == 0, listed.stderr
    builtin = [line.split()[0] for line in listed.stdout.splitlines()]
    assert "brickworld" in builtin
    r = nanohaptics("run", "no-such-scene", cwd=scratch)
    assert r.returncode == 1 and r.stdout == ""
    assert r.stderr == (
        "error: cannot read no-such-scene: no such file, and not a built-in scene (built-in: "
        f"{', '.join(builtin)}; `nanohaptics scenes export DIR` writes editable copies)\n"
    )


def test_the_function_returns_the_status_instead_of_ending_python(scratch):
    code = (
        "from nanohaptics.nanohaptics import _cli\n"
        "print('status', _cli(['nanohaptics', '--version']))\n"
        "print('status', _cli(['nanohaptics', 'run', '--no-such-flag']))\n"
    )
    r = subprocess.run(
        [sys.executable, "-c", code], cwd=scratch, capture_output=True, text=True, timeout=60
    )
    assert r.returncode == 0, r.stderr
    assert r.stdout == f"nanohaptics {nh.__version__}\nstatus 0\nstatus 2\n"
    assert r.stderr.startswith("error: unexpected argument '--no-such-flag' found\n")


def test_a_closed_pipe_ends_the_command_with_141(scratch):
    # `nanohaptics scenes | head -0`, deterministically: the pipe has no reader from the start.
    read_end, write_end = os.pipe()
    os.close(read_end)
    try:
        r = subprocess.run(
            [str(COMMAND), "scenes"], cwd=scratch, stdout=write_end, stderr=subprocess.PIPE,
            text=True, timeout=60,
        )
    finally:
        os.close(write_end)
    # Quietly, as the binary: no panic message about a failed print.
    assert (r.returncode, r.stderr) == (141, "")


def test_ctrl_c_stops_run_cleanly_with_a_verifiable_recording(scratch, sigint_raises):
    p = subprocess.Popen(
        [str(COMMAND), "run", "brickworld", "--realtime", "--seconds", "30", "--out", "rec.mcap"],
        cwd=scratch, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True,
    )
    try:
        # The recording's file appears once the session runs (its Ctrl-C handler is set).
        wait_for(scratch / "rec.mcap", p, 60)
        time.sleep(1.0)
        took = interrupt(p)
        out, err = p.communicate(timeout=10)
    finally:
        end(p)
    assert p.returncode == 130, err
    assert took < 5, f"{took:.1f} s after Ctrl-C"
    m = re.search(
        r"^stopped by an interrupt after (\d+) ticks; rec\.mcap holds them, complete and "
        r"verifiable$", err, re.M,
    )
    assert m, err
    ticks = int(m.group(1))
    assert 0 < ticks < 30_000 and f"  {ticks} ticks (" in out
    v = nanohaptics("replay", "rec.mcap", "--verify", cwd=scratch)
    assert v.returncode == 0, v.stderr
    assert v.stdout.startswith(f"rec.mcap: {ticks} ticks replayed, ")


def page_files(text: str, name: str) -> set[str]:
    """The page's own files a page file names: the HTML's links and scripts, a module's
    imports."""
    if name.endswith(".html"):
        found = re.findall(r'(?:href|src)="/([A-Za-z0-9_.-]+\.(?:css|js))"', text)
    else:
        found = re.findall(r"""\bfrom\s+['"]\./([A-Za-z0-9_.-]+\.js)['"]""", text)
    return set(found)


def test_play_serves_the_built_in_page_and_ctrl_c_ends_it(scratch, sigint_raises):
    p = subprocess.Popen(
        [str(COMMAND), "play", "--port", "0", "--out", "play.mcap"],
        cwd=scratch, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True,
    )
    stdout = Lines(p.stdout)
    try:
        line = stdout.next(60)
        m = re.fullmatch(r"open (http://127\.0\.0\.1:\d+/) in a browser \(Ctrl-C ends the session\)\n", line)
        assert m, line
        url = m.group(1)
        with urllib.request.urlopen(url, timeout=10) as r:
            assert r.status == 200 and r.headers["Content-Type"].startswith("text/html")
            body = r.read().decode("utf-8")
        # The page is built into the program: every file it loads is served from the scratch
        # folder, identical to the source.
        assert body == (PAGE / "index.html").read_text(encoding="utf-8")
        todo, seen = page_files(body, "index.html"), set()
        assert {"play.css", "main.js"} <= todo
        while todo:
            name = todo.pop()
            seen.add(name)
            with urllib.request.urlopen(url + name, timeout=10) as r:
                assert r.status == 200, name
                text = r.read().decode("utf-8")
            assert text == (PAGE / name).read_text(encoding="utf-8"), name
            todo |= page_files(text, name) - seen
        assert len(seen) >= 4, seen
        took = interrupt(p)
        out, err = stdout.rest(), p.stderr.read()
    finally:
        end(p, stdout)
    assert took < 5, f"{took:.1f} s after Ctrl-C"
    # As the binary: no page pressed Start, so the session ends with this error and no file.
    assert (p.returncode, out, err) == (
        1, "", "error: stopped before a page started the session: nothing was recorded\n"
    )
    assert not (scratch / "play.mcap").exists()


def test_classroom_serves_the_class_and_ctrl_c_ends_it(scratch, sigint_raises):
    p = subprocess.Popen(
        [str(COMMAND), "classroom", "--port", "0", "--out-dir", "class"],
        cwd=scratch, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True,
    )
    stdout = Lines(p.stdout)
    try:
        head = [stdout.next(60) for _ in range(4)]
        assert head[0] == "classroom: up to 40 students, recordings in class\n", head
        student = re.fullmatch(
            r"  students open  (http://127\.0\.0\.1:\d+/)  \(on this computer a name is enough\)\n",
            head[1],
        )
        teacher = re.fullmatch(
            r"  teacher page   (http://127\.0\.0\.1:\d+/teacher\?code=(\w+))  \(keep its code, "
            r"(\w+), to yourself\)\n",
            head[2],
        )
        assert student and teacher and teacher.group(2) == teacher.group(3), head
        assert head[3] == "Ctrl-C ends every session and prints the class's figures.\n"
        # The join page and the teacher page come from inside the program.
        for url in (student.group(1), teacher.group(1)):
            with urllib.request.urlopen(url, timeout=10) as r:
                assert r.status == 200 and r.headers["Content-Type"].startswith("text/html"), url
                assert "<html" in r.read().decode("utf-8").lower(), url
        took = interrupt(p)
        out, err = stdout.rest(), p.stderr.read()
    finally:
        end(p, stdout)
    assert took < 5, f"{took:.1f} s after Ctrl-C"
    # As the binary: Ctrl-C ends every session and prints the class's figures (none joined).
    assert (p.returncode, err) == (0, ""), err
    # The first line says how many sessions, on how many tick workers, with what real time.
    first, rest = out.split("\n", 1)
    assert re.fullmatch(r"0 student sessions on \d tick workers?; real time: .+", first), out
    assert rest.startswith("refused: 0 in all (0 host, 0 origin, "), out


def test_classroom_lesson_serves_the_builtin_module_and_writes_the_class_report(
    scratch, sigint_raises
):
    p = subprocess.Popen(
        [str(COMMAND), "classroom", "--lesson", "--port", "0", "--out-dir", "class"],
        cwd=scratch, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True,
    )
    stdout = Lines(p.stdout)
    try:
        head = [stdout.next(60) for _ in range(5)]
        assert head[0] == "classroom: up to 40 students, recordings in class\n", head
        assert head[1] == (
            "  lesson         Forces at the nanoscale (11 steps; the teacher page opens the "
            "locked ones)\n"
        ), head
        student = re.fullmatch(
            r"  students open  (http://127\.0\.0\.1:\d+/)  \(on this computer a name is enough\)\n",
            head[2],
        )
        assert student, head
        with urllib.request.urlopen(student.group(1), timeout=10) as r:
            assert "Lesson: <b>Forces at the nanoscale</b>" in r.read().decode("utf-8")
        took = interrupt(p)
        out, err = stdout.rest(), p.stderr.read()
    finally:
        end(p, stdout)
    assert took < 5, f"{took:.1f} s after Ctrl-C"
    assert (p.returncode, err) == (0, ""), err
    # The class report of nobody, written where the recordings go, and said.
    assert "class report: class/class-report.md\n" in out, out
    steps = (scratch / "class" / "class-steps.csv").read_text()
    assert steps == (
        "student,step,step_id,step_title,state,seconds,met_at_s,peak_force_n,score,before,after\n"
    )


def test_ctrl_c_ends_a_command_without_its_own_handler_at_once(scratch, sigint_raises):
    # fake-device waits up to 30 s for a simulator's welcome; this socket never answers.
    with socket.socket(socket.AF_INET, socket.SOCK_DGRAM) as silent:
        silent.bind(("127.0.0.1", 0))
        port = silent.getsockname()[1]
        p = subprocess.Popen(
            [str(COMMAND), "fake-device", f"udp:127.0.0.1:{port}", "--wait-s", "30"],
            cwd=scratch, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True,
        )
        stderr = Lines(p.stderr)
        try:
            assert stderr.next(60) == f"fake-device: saying hello to 127.0.0.1:{port} ...\n"
            took = interrupt(p)
        finally:
            end(p, stderr)
    # Ended by the signal, as the binary is (a shell reports 130), not after the 30 s wait.
    assert p.returncode == -signal.SIGINT
    assert took < 2, f"{took:.1f} s after Ctrl-C"


def readme_teacher_section() -> str:
    text = (ROOT / "README.md").read_text(encoding="utf-8")
    m = re.search(r"^## For a teacher\n(.*?)(?=^## )", text, re.M | re.S)
    assert m, "README.md has no '## For a teacher' section"
    return m.group(1)


def test_the_readmes_teacher_lines_name_the_wheel_and_real_commands(scratch):
    section = readme_teacher_section()
    block = re.search(r"```sh\n(.*?)```", section, re.S)
    assert block, section
    assert block.group(1).splitlines() == ["pip install nanohaptics", "nanohaptics classroom"]
    # The commands it names: `nanohaptics CMD` in the prose, or a block's line of its own.
    named = set(re.findall(r"(?:`|^)nanohaptics ([a-z][a-z-]*)", section, re.M))
    section = " ".join(section.split())  # the prose, whatever its line breaks
    # Today's wheel: the file scripts/test.sh builds and installs.
    (built,) = re.findall(r"pip install [^\n]*?(target/wheels-test/\S+\.whl)", (ROOT / "scripts" / "test.sh").read_text())
    assert f"`pip install {built}`" in section, section
    have = set(commands_in_help(nanohaptics("--help", cwd=scratch).stdout))
    assert named >= {"classroom", "play"}, named
    for cmd in sorted(named - {"classroom"}):
        assert cmd in have, f"README's teacher section names `nanohaptics {cmd}`, no such command"
    # `classroom` is being built (issue 32, item 2): the README says so until it exists.
    pending = "`nanohaptics classroom` is being built" in section
    assert pending == ("classroom" not in have), (
        "README.md's teacher section: say that `nanohaptics classroom` is being built exactly "
        "while the program lacks it"
    )
