"""Recordings and faults (issue 11, items 16, 18, 19): a damaged recording is a ValueError that
names the record and its byte offset; a salvage that recovers no tick is an error; a full disk
is an OSError with the OS's errno, the path and how many ticks reached the disk."""

import os
import pathlib
import struct

import pytest

import nanohaptics as nh

ROOT = pathlib.Path(__file__).resolve().parents[2]
GOLDEN = ROOT / "recordings" / "wall.mcap"


def records(b):
    """Top-level MCAP records: (opcode, offset, end)."""
    out, at = [], 8
    while at + 9 <= len(b):
        (n,) = struct.unpack_from("<Q", b, at + 1)
        out.append((b[at], at, at + 9 + n))
        if b[at] == 0x02:
            break
        at += 9 + n
    return out


@pytest.mark.skipif(not os.path.exists("/dev/full"), reason="needs /dev/full (Linux)")
def test_a_full_disk_is_an_oserror_with_the_os_error_the_path_and_the_ticks():
    with pytest.raises(OSError) as e:
        nh.run_scene("wall", seconds=0.1, out="/dev/full")
    assert e.value.errno == 28
    assert e.value.strerror == (
        "recording /dev/full: No space left on device (os error 28); "
        "0 ticks reached the disk"
    )


def test_a_salvage_that_recovers_no_tick_is_an_error(tmp_path):
    b = GOLDEN.read_bytes()
    chunk = [r for r in records(b) if r[0] == 0x06][1]
    cut = tmp_path / "cut.mcap"
    cut.write_bytes(b[: chunk[1] + 100])
    (n,) = struct.unpack_from("<Q", b, chunk[1] + 1)
    with pytest.raises(ValueError) as e:
        nh.read_recording(cut, salvage=True)
    assert str(e.value) == (
        f"nothing to salvage: the chunk record at byte {chunk[1]} announces {n} bytes, "
        "the file ends 91 bytes into it, before the end of its first tick"
    )


def test_a_changed_byte_names_the_record_and_offset(tmp_path):
    b = bytearray(GOLDEN.read_bytes())
    st = [r for r in records(b) if r[0] == 0x0B][0]
    b[st[1] + 9] ^= 1  # the statistics' message count, covered by the summary CRC
    p = tmp_path / "changed.mcap"
    p.write_bytes(bytes(b))
    with pytest.raises(ValueError) as e:
        nh.read_recording(p)
    footer = [r for r in records(b) if r[0] == 0x02][0][1]
    assert str(e.value).startswith(f"corrupt recording: footer at byte {footer}: the CRC-32 of")
    assert str(e.value).endswith("(the summary was changed)")
