#!/usr/bin/env python3
"""Convert the shared settled bed (one disk a line: x y radius) to a LAMMPS data file.

atom_style sphere, 2D: Atoms columns are  id type diameter density x y z  (z = 0).
Box: x [0, 100] (periodic in the input deck), y [0, YHI] (fixed, floor wall at y = 0), z [-0.5, 0.5].

--mass disk (default): mass = pi r^2 (areal density 1, as seep's bench).  LAMMPS 29Sep2021
(Debian 20220106) sets the per-atom mass from the data-file density as 4/3 pi r^3 * density even
with `dimension 2` (checked with `compute property/atom mass`, see in.checkmass), so this writes
density = 0.75 / r  =>  4/3 pi r^3 * 0.75/r = pi r^2  (max |mass - pi r^2| = 3e-16).
--mass sphere: density 1, i.e. mass = 4/3 pi r^3.  NOTE: the shared bed was settled with this
mass: the floor overlaps of settled_bed_9900.txt give kn * sum(r - y) = 38300.4 = g * sum(4/3 pi
r^3) (g * sum(pi r^2) = 63290.4), so with mass pi r^2 the bed is not in equilibrium and compacts.

usage: bed_to_lammps.py settled_bed_9900.txt out.data [--yhi 110] [--mass disk|sphere]
"""
import argparse
import math


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("bed")
    ap.add_argument("out")
    ap.add_argument("--yhi", type=float, default=110.0)
    ap.add_argument("--lx", type=float, default=100.0)
    ap.add_argument("--mass", choices=["disk", "sphere"], default="disk")
    a = ap.parse_args()

    disks = []
    with open(a.bed) as f:
        for line in f:
            s = line.strip()
            if not s or s.startswith("#"):
                continue
            x, y, r = (float(v) for v in s.split()[:3])
            disks.append((x, y, r))
    ymax = max(y + r for _, y, r in disks)
    if ymax >= a.yhi:
        raise SystemExit(f"top of bed {ymax} >= yhi {a.yhi}")

    with open(a.out, "w") as o:
        o.write(f"LAMMPS data: {len(disks)} disks from {a.bed} (--mass {a.mass})\n\n")
        o.write(f"{len(disks)} atoms\n1 atom types\n\n")
        o.write(f"0 {a.lx:.17g} xlo xhi\n0 {a.yhi:.17g} ylo yhi\n-0.5 0.5 zlo zhi\n\n")
        o.write("Atoms # sphere\n\n")
        for i, (x, y, r) in enumerate(disks, 1):
            x = x % a.lx
            rho = 0.75 / r if a.mass == "disk" else 1.0
            o.write(f"{i} 1 {2.0 * r:.17g} {rho:.17g} {x:.17g} {y:.17g} 0\n")
    if a.mass == "disk":
        mass = sum(math.pi * r * r for _, _, r in disks)
    else:
        mass = sum(4.0 / 3.0 * math.pi * r ** 3 for _, _, r in disks)
    print(f"wrote {a.out}: {len(disks)} disks, top {ymax:.3f}, mass {a.mass}, total {mass:.6f}")


if __name__ == "__main__":
    main()
