# The `nanohaptics` command of the wheel (pyproject.toml's [project.scripts] entry) and
# `python -m nanohaptics`: the program of the Rust crate nanohaptics-cli, which the extension
# carries and runs in this process (crates/ot-py/src/cli.rs). Same commands, output and exit
# statuses as the `nanohaptics` binary.

import signal
import sys

from .nanohaptics import _cli


def main() -> None:
    """Runs the `nanohaptics` program with this process's arguments and exits with its status."""
    # Ctrl-C as for the binary. Python's own SIGINT handler only marks the signal for the
    # interpreter, which does not look while the program runs (the GIL is released), so the
    # disposition goes back to the default: a command that watches SIGINT itself (`run`,
    # `play`) installs its handler over it, stops cleanly and finishes its recording (status
    # 130 for `run`); any other command ends at once, as the binary does (the shell's 130).
    # An inherited "ignore" (nohup, `trap '' INT`) is kept, as the binary keeps it.
    if signal.getsignal(signal.SIGINT) is signal.default_int_handler:
        signal.signal(signal.SIGINT, signal.SIG_DFL)
    sys.exit(_cli(["nanohaptics", *sys.argv[1:]]))


if __name__ == "__main__":
    main()
