"""scripts/layering.py: the crate map is exact and a dev-dependency must not close a cycle
(issue 34, part 6). Needs only Python (tomllib: 3.11 or later), not the wheel."""

import subprocess
import sys
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[2]
SCRIPT = ROOT / "scripts" / "layering.py"

pytestmark = pytest.mark.skipif(sys.version_info < (3, 11), reason="layering.py reads TOML with tomllib")


def layering(crates_dir):
    return subprocess.run(
        [sys.executable, str(SCRIPT), str(crates_dir)], capture_output=True, text=True, timeout=120
    )


def crate(crates_dir, folder, name, deps=(), dev=()):
    """A crate folder holding only a Cargo.toml with path dependencies on its siblings."""
    d = crates_dir / folder
    d.mkdir(parents=True)
    lines = [f'[package]\nname = "{name}"\nversion = "0.1.0"\n', "[dependencies]"]
    lines += [f'{x} = {{ path = "../{x}" }}' for x in deps]
    lines += ["", "[dev-dependencies]"]
    lines += [f'{x} = {{ path = "../{x}" }}' for x in dev]
    (d / "Cargo.toml").write_text("\n".join(lines) + "\n")
    return d / "Cargo.toml"


def test_a_dev_dependency_closing_a_cycle_fails_naming_it(tmp_path):
    # `chart` depends on `picture` (as ALLOWED grants); `picture` dev-depends on `chart`.
    crate(tmp_path, "chart", "chart", deps=["picture"])
    manifest = crate(tmp_path, "picture", "picture", dev=["chart"])
    out = layering(tmp_path)
    assert out.returncode == 1, out.stdout + out.stderr
    assert out.stdout.splitlines() == [
        f"{manifest}: dev-dependency cycle: `picture` dev-depends on `chart`, and "
        "chart -> picture through [dependencies]"
    ]


def test_a_cycle_through_several_crates_is_named_whole(tmp_path):
    # picture -(dev)-> bench-harness -> chart -> picture
    crate(tmp_path, "picture", "picture", dev=["bench-harness"])
    crate(tmp_path, "chart", "chart", deps=["picture"])
    crate(tmp_path, "world-form", "world-form")
    crate(tmp_path, "bench-harness", "bench-harness", deps=["chart", "world-form"])
    out = layering(tmp_path)
    assert out.returncode == 1, out.stdout + out.stderr
    assert out.stdout.splitlines() == [
        f"{tmp_path / 'picture' / 'Cargo.toml'}: dev-dependency cycle: `picture` dev-depends on "
        "`bench-harness`, and bench-harness -> chart -> picture through [dependencies]"
    ]


def test_a_dev_dependency_from_below_is_free(tmp_path):
    # `chart` dev-depending on `world-form` closes no cycle; the map is exact.
    crate(tmp_path, "picture", "picture")
    crate(tmp_path, "world-form", "world-form")
    crate(tmp_path, "chart", "chart", deps=["picture"], dev=["world-form"])
    out = layering(tmp_path)
    assert out.returncode == 0, out.stdout + out.stderr
    assert out.stdout.startswith("layering: 3 crates")


def test_a_grant_no_dependency_uses_fails(tmp_path):
    manifest = crate(tmp_path, "chart", "chart")  # ALLOWED grants it `picture`
    crate(tmp_path, "picture", "picture")
    out = layering(tmp_path)
    assert out.returncode == 1
    assert out.stdout.splitlines() == [
        f"{manifest}: ALLOWED (scripts/layering.py) grants `chart` `picture`, which its "
        "[dependencies] do not use: remove the grant"
    ]


def test_the_workspace_passes():
    out = layering(ROOT / "crates")
    assert out.returncode == 0, out.stdout + out.stderr
    assert "no dev-dependency cycles" in out.stdout
