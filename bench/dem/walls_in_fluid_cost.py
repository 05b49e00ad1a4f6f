#!/usr/bin/env python3
"""What the walls in the fluid cost a coupled step (issue #15: at most 5 % on the coupled share bench).

Since the walls bound the fluid there is no scene in which they do not, so the comparison is with
the build from before they did (1ea7d15, the last commit before the walls entered the fluid model:
the same bed and walls, but the pores along the walls were no domains). The script builds that
revision's seep_coupled_share_bench in a temporary worktree, then runs the two binaries alternately
(ABAB..., so that drift of the machine's load falls on both alike) and prints, per thread count, the
median and minimum coupled and mechanics seconds of each and their ratios.

Usage: walls_in_fluid_cost.py NEW_BENCH BED [--rounds 7] [--steps 5000] [--base 1ea7d15]
(5000 steps at most: the bench scene ends at 1 s of simulated time, dt 1e-4, after 200 warm-up steps)
       [--base-bench PATH]  (skip the build: a bench binary of the base revision)
"""
import argparse
import os
import re
import statistics
import subprocess
import sys
import tempfile

LINE = re.compile(r"^(mechanics|coupled)\s+(\d) thread\(s\), .*steps: ([0-9.]+) s,")


def build_base(revision: str, workdir: str) -> str:
    repo = subprocess.run(["git", "rev-parse", "--show-toplevel"], check=True, text=True,
                          capture_output=True, cwd=os.path.dirname(os.path.abspath(__file__))).stdout.strip()
    tree = os.path.join(workdir, "base")
    subprocess.run(["git", "-C", repo, "worktree", "add", "-q", "--detach", tree, revision], check=True)
    try:
        build = os.path.join(tree, "build")
        subprocess.run(["cmake", "-S", tree, "-B", build, "-G", "Ninja", "-DCMAKE_BUILD_TYPE=Release",
                        "-DSEEP_BUILD_SERVICE=OFF", "-DSEEP_BUILD_TESTS=OFF"], check=True,
                       stdout=subprocess.DEVNULL)
        subprocess.run(["cmake", "--build", build, "--target", "seep_coupled_share_bench"], check=True,
                       stdout=subprocess.DEVNULL)
        binary = os.path.join(workdir, "base_bench")
        os.replace(os.path.join(build, "bench", "dem", "seep_coupled_share_bench"), binary)
        return binary
    finally:
        subprocess.run(["git", "-C", repo, "worktree", "remove", "--force", tree], check=False)


def run_once(binary: str, bed: str, steps: int) -> dict:
    out = subprocess.run([binary, bed, str(steps)], check=True, text=True, capture_output=True).stdout
    seconds = {}
    for line in out.splitlines():
        m = LINE.match(line)
        if m:
            seconds[(m.group(1), int(m.group(2)))] = float(m.group(3))
    if len(seconds) != 4:
        sys.exit(f"{binary}: unexpected output:\n{out}")
    return seconds


def main() -> None:
    p = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("new_bench")
    p.add_argument("bed")
    p.add_argument("--rounds", type=int, default=7)
    p.add_argument("--steps", type=int, default=5000)
    p.add_argument("--base", default="1ea7d15")
    p.add_argument("--base-bench")
    a = p.parse_args()
    with tempfile.TemporaryDirectory() as workdir:
        base = a.base_bench or build_base(a.base, workdir)
        runs = {"walls in fluid": [], "base " + a.base: []}
        for r in range(a.rounds):
            # Alternate which goes first, so neither always runs on a warmer machine.
            order = [("walls in fluid", a.new_bench), ("base " + a.base, base)]
            for name, binary in (order if r % 2 == 0 else order[::-1]):
                runs[name].append(run_once(binary, a.bed, a.steps))
            print(f"round {r + 1}/{a.rounds} done", file=sys.stderr)
    new, old = runs["walls in fluid"], runs["base " + a.base]
    print(f"{a.rounds} alternating rounds of {a.steps} timed steps on {a.bed}")
    for threads in (1, 2):
        for kind in ("mechanics", "coupled"):
            n = [s[(kind, threads)] for s in new]
            o = [s[(kind, threads)] for s in old]
            print(f"{threads} thread(s) {kind:9s}: walls in fluid median {statistics.median(n):.3f} s "
                  f"min {min(n):.3f} s | base median {statistics.median(o):.3f} s min {min(o):.3f} s "
                  f"| ratio median {statistics.median(n) / statistics.median(o):.3f} "
                  f"min {min(n) / min(o):.3f}")
    print("goal: coupled ratio <= 1.05 (issue #15)")


if __name__ == "__main__":
    main()
