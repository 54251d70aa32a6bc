"""A braced pair for the random weldment (``tools/random_cell_weldment.py``): two plates standing parallel on the base
and a flat bar lying on the base between them at 20-70 degrees to them, both its ends mitred to lie flat on the
plates' inner faces (the ladder's brace in small) [mm, frame M, z up].

Seams: each plate's fillet on the base on its outer side (the inner one runs under the brace's ends); at each brace
end on the plate's face, its top fillet (90 degrees) and those of its cheeks (the brace's angle and its supplement)
where they are long enough and a torch fits (``random_cell_members.DIHEDRAL_RANGE_DEG``). The bottom fillet lies on
the base: not drawn.
"""

from __future__ import annotations

import math

import numpy as np
from random_cell_members import DIHEDRAL_RANGE_DEG, MIN_SEAM_MM, Member, capsule, standing
from random_cell_parts import Body, Seam, moved, pose, prism, rot_z, vec


def braced_pair(
    rng: np.random.Generator, names: tuple[str, str, str], xy: tuple[float, float], yaw: float, z_top: float
) -> tuple[list[Member], tuple[float, float, float, float, float]] | None:
    """Plates ``names[0]``, ``names[1]`` and brace ``names[2]`` about the centre ``xy``, the plates along the turned
    x (``yaw`` [deg]); the members and the footprint of the whole. None when the brace does not fit the plates."""
    length, thick, height = rng.uniform(160, 260), float(rng.choice([8, 10, 12])), rng.uniform(50, 120)
    clear, alpha = rng.uniform(70, 150), rng.uniform(20, 70)
    width, bar = rng.uniform(25, 40), float(rng.choice([8, 10, 12]))
    g_bar, g_ends = (
        round(float(rng.uniform(0, 2)), 1),
        (round(float(rng.uniform(0, 2)), 1), round(float(rng.uniform(0, 2)), 1)),
    )
    sa, ca = math.sin(math.radians(alpha)), math.cos(math.radians(alpha))
    yl, yr = -clear / 2 + g_ends[0], clear / 2 - g_ends[1]  # the brace's mitred ends

    def x_at(y: float, side: float) -> float:  # where the band's side (+-1) crosses the line at y
        return (y * ca + side * width / 2) / sa

    if x_at(yr, 1) - x_at(yl, -1) > length - 40 or bar > height - 20:
        return None
    X = pose(rot_z(yaw), (xy[0], xy[1], 0.0))
    R = X[:3, :3]
    plates = []
    for name, sign, face in ((names[0], -1.0, "-y"), (names[1], 1.0, "+y")):
        c = moved(X, (0.0, sign * (clear / 2 + thick / 2), 0.0))
        gap = round(float(rng.uniform(0, 2)), 1)
        plates.append(standing(name, "plate", (length, thick, height), (c[0], c[1]), yaw, "BASE", z_top, gap, (face,)))
    outline = [(x_at(yl, -1), yl), (x_at(yl, 1), yl), (x_at(yr, 1), yr), (x_at(yr, -1), yr)]
    z0 = z_top + g_bar
    v, f = prism(outline, z0, z0 + bar, X)
    brace_len = math.hypot(x_at(yr, 0) - x_at(yl, 0), yr - yl)
    extra = {"angle_to_plates_deg": alpha, "slide_deg": yaw}
    centre = moved(X, (0.0, 0.0, z0 + bar / 2))
    body = Body(names[2], "brace", v, f, vec(centre), (0.0, 0.0, yaw + alpha), (brace_len, width, bar), extra=extra)
    m_W = R @ np.array([sa, -ca, 0.0])  # the band's side +1's outward normal
    seams = []
    for plate, y, n_b in ((names[0], -clear / 2, R[:, 1]), (names[1], clear / 2, -R[:, 1])):
        ye = yl if plate == names[0] else yr
        lo, hi = x_at(ye, -1), x_at(ye, 1)  # the end's edge; a cheek's plane meets the face at x_at(y)
        for face, a, b, n_a in (
            ("top", (lo, y, z0 + bar), (hi, y, z0 + bar), np.array([0.0, 0.0, 1.0])),
            ("cheek-", (x_at(y, -1), y, z0), (x_at(y, -1), y, z0 + bar), -m_W),
            ("cheek+", (x_at(y, 1), y, z0), (x_at(y, 1), y, z0 + bar), m_W),
        ):
            deg = 180.0 - math.degrees(math.acos(max(-1.0, min(1.0, float(n_a @ n_b)))))
            p0, p1 = vec(moved(X, a)), vec(moved(X, b))
            if DIHEDRAL_RANGE_DEG[0] <= deg <= DIHEDRAL_RANGE_DEG[1] and math.dist(p0, p1) >= MIN_SEAM_MM:
                seams.append(Seam(f"{names[2]}>{plate}:{face}", p0, p1, names[2], plate, deg))
    brace = Member(body, tuple(seams), capsule(X, length, clear))
    return [*plates, brace], capsule(X, length, clear + 2 * thick)
