"""The C reference in docs/device-bridge.md compiles as printed and follows the document's
rules: rule 2's ticks (unsigned, the offset signed, the last packet), a plane's force, a
version-1 answer that keeps the body without rendering its pull (issue 41), version 3's
bond, which holds in pull and in press and breaks at its stretch, and version 4's follower,
which pushes on the excess only, clips from the free drift when zero is out of reach, and
drifts by what it keeps of its end velocity (the figures of crates/types' follower tests)."""

import re
import shutil
import subprocess
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[2]
OUT = ROOT / "target" / "c-reference"

MAIN = r"""
#include <stdio.h>
int main(void) {
    nh_ticks k = {0};
    uint64_t next = 0;
    int ok = nh_accept(&k, 0, 3, &next);            /* tick 0 read sample 3: first = 3 */
    printf("%d %lld %llu\n", ok, (long long)k.offset, (unsigned long long)next);
    ok = nh_accept(&k, 5, 6, &next);                /* a stale tick: t - a = -1 > -3 */
    printf("%d %lld %llu\n", ok, (long long)k.offset, (unsigned long long)next);
    ok = nh_accept(&k, 4, 7, &next);                /* older than tick 5: dropped */
    printf("%d %lld\n", ok, (long long)k.offset);
    ok = nh_accept(&k, UINT64_MAX, 9, &next);       /* the last packet */
    printf("%d %lld\n", ok, (long long)k.offset);

    nh_side s = {0};
    s.protocol = 2; s.max_force_n = 8.0; s.period_s = 1e-3;
    s.have_answer = 1; s.model = 1;
    s.planes[0] = (nh_plane){{0.0, 0.0, 1.0}, -0.005, 5000.0}; s.n_planes = 1;
    double p[3] = {0.0, 0.0, -0.006}, f[3];
    nh_render(&s, p, 2.5e-4, f);
    printf("%.6f\n", f[2]);
    /* A body 1 mm below the stylus: a version-2 answer renders its pull, a version-1 one not. */
    s.n_planes = 0;
    s.have_body = 1;
    s.body.mass_kg = 1.0; s.body.stiffness_n_per_m = 100.0; s.body.substeps = 1;
    s.body.position_m[2] = -0.007;
    nh_render(&s, p, 2.5e-4, f);
    printf("%.6f\n", f[2]);
    s.model = 0;
    nh_render(&s, p, 2.5e-4, f);
    printf("%.6f %d\n", f[2], s.have_body);
    /* Version 3's bond: 500 N/m anchored at 0, breaking at 2 mm of pull or shear. */
    double a[3] = {0.0, 0.0, 0.0}, n[3] = {0.0, 0.0, 1.0};
    double pulls[3][3] = {{0.0, 0.0, 0.0015}, {0.0, 0.0, 0.0025}, {0.0, 0.0, -0.003}};
    for (int j = 0; j < 3; j++) {
        double g[3] = {0.0, 0.0, 0.0};
        nh_bond_add(a, n, 500.0, 0.002, pulls[j], g);
        printf("%.6f\n", g[2]);
    }
    /* Version 4's follower: the square of half-width 1 mm, 100 N/m, retain 0.1. */
    nh_follower fo = {{0.0, 0.0}, {0.0, 0.0}, 0.1, 100.0, 4,
                      {{1e-3, -1e-3}, {1e-3, 1e-3}, {-1e-3, 1e-3}, {-1e-3, -1e-3}}};
    double inside[3] = {0.5e-3, 0.0, 0.0}, beyond[3] = {3e-3, 0.0, 0.0}, far[3] = {0.1, 0.0, 0.0};
    double g1[3] = {0.0, 0.0, 0.0}, g2[3] = {0.0, 0.0, 0.0};
    nh_follower_add(&fo, inside, g1);
    nh_follower_add(&fo, beyond, g2);
    printf("%.6f %.6f\n", g1[0], g2[0]);
    nh_follower drifting = fo;
    drifting.u[0] = 2e-3;
    double d5[2] = {5e-3, 1e-3}, c5[2];
    nh_follower_clip(&drifting, d5, c5);
    printf("%.6f %.6f\n", c5[0] * 1e3, c5[1] * 1e3);
    nh_follower_step(&fo, far);
    printf("%.6f %.6f\n", fo.x[0] * 1e3, fo.u[0] * 1e3);
    nh_follower_step(&fo, far);
    printf("%.6f %.6f\n", fo.x[0] * 1e3, fo.u[0] * 1e3);
    return 0;
}
"""


def c_reference() -> str:
    doc = (ROOT / "docs" / "device-bridge.md").read_text()
    blocks = re.findall(r"```c\n(.*?)```", doc, re.S)
    # The reference (versions 1 and 2), then version 3's bond and version 4's follower, which
    # the document prints first.
    reference = [b for b in blocks if "nh_accept" in b]
    bond = [b for b in blocks if "nh_bond_add" in b]
    follower = [b for b in blocks if "nh_follower_step" in b]
    assert (len(blocks), len(reference), len(bond), len(follower)) == (3, 1, 1, 1)
    return reference[0] + "\n" + bond[0] + "\n" + follower[0]


@pytest.mark.skipif(shutil.which("cc") is None, reason="no C compiler")
def test_the_c_reference_compiles_and_follows_the_rules():
    OUT.mkdir(parents=True, exist_ok=True)
    src = OUT / "nh.c"
    src.write_text(c_reference() + MAIN)
    exe = OUT / "nh"
    subprocess.run(["cc", "-std=c99", "-Wall", "-Werror", "-ffp-contract=off", "-o", str(exe),
                    str(src), "-lm"], check=True)
    out = subprocess.run([str(exe)], check=True, capture_output=True, text=True).stdout
    assert out.splitlines() == [
        "1 -3 4",   # o = t - a = -3 (signed); tick 0's body meets sample t - o + 1 = 4
        "1 -3 9",   # a stale tick does not move o; tick 5's body meets sample 9
        "0 -3",     # an older tick is dropped
        "1 -3",     # the last packet is taken and does not move o
        "5.000000",  # the wall: 5000 N/m, 1 mm in
        "-0.100000",  # the body's pull: 100 N/m over 1 mm, felt downwards
        "0.000000 1",  # a version-1 answer: F0 - K (p - p0) = 0, the body kept
        "-0.750000",  # the bond holds at 1.5 mm of pull: 0.75 N back
        "0.000000",  # broken at 2.5 mm
        "1.500000",  # 3 mm pressed in: it holds, pushing out
        "0.000000 -0.200000",  # inside the envelope nothing; 2 mm beyond, 0.2 N back
        "3.000000 0.333333",  # from the free drift (2 mm): the edge x = 3 mm at y = 1/3 mm
        "1.000000 0.200000",  # from rest: 1 mm, the drift 0.1 (2 - 0) = 0.2 mm
        "2.200000 0.220000",  # the envelope moved by the drift: 1.2 mm more, drift 0.22 mm
    ]
