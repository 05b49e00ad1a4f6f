#!/usr/bin/env python3
"""The instructions a coupled step executes per effect (issue 19: flow share <= 25 % at 1:1).

Runs seep_coupled_share_bench on one thread under valgrind's callgrind (no hardware counters
needed: many virtual machines expose none) and prints, per DEM step of the settled bed, the instructions of
each effect the stepper calls: the mechanics ones (called in both of the bench's runs) and the
fluid ones (the coupled run only), with the exact-volume pass's edge terms apart. A flow share of
25 % means the fluid effects take a third of the mechanics' time; if they ran at the mechanics'
instructions per cycle, that is a third of the mechanics' instructions. The script prints that
allowance next to what the fluid effects execute: how far the 25 % is from the arithmetic the
examples' bits need (every coupled pass keeps its operations, see seep_example_states
--nudge-bulk-modulus), whatever the scheduling.

Usage: instruction_budget.py BENCH BED [--steps 300]
  BENCH  a Release build's bench/dem/seep_coupled_share_bench
  BED    bench/settled_bed_9900.txt
Takes about 25 s at 300 steps (valgrind runs the bench some 50x slower).
"""
import argparse
import os
import re
import shutil
import subprocess
import sys
import tempfile

# A callee line of Stepper::Step in callgrind_annotate's calling tree:
#   "2,676,924,209 (44.03%)  >   ???:ns::ContactsEffect::AddForces(...) (1,000x) [binary]"
CALLEE = re.compile(r"^\s*([0-9,]+) \(\s*[0-9.]+%\)\s+>\s+\S*?:(.*) \(([0-9,]+)x\)")
STEP = re.compile(r"^\s*[0-9,]+ \(\s*[0-9.]+%\)\s+\*\s+\S*?:seep::core::Stepper::Step\(\)")
FLAT = re.compile(r"^\s*([0-9,]+) \(\s*[0-9.]+%\)\s+\S*?:(.*)")

FLUID = {
    "VolumeChangeEffect::EndOfStep": "volume change",
    "FluidForcesEffect::AddForces": "fluid forces",
    "FlowEffect::EndOfStep": "flow",
    "ApertureUpdateEffect::EndOfStep": "apertures",
}
MECHANICS = {
    "ContactsEffect::AddForces": "contacts",
    "IntegrateFirstHalf": "integration",
    "IntegrateSecondHalf": "integration",
    "GravityEffect::AddForces": "gravity",
    "WallsEffect::PostForce": "walls",
    "MoveWalls": "walls",
}


def number(text: str) -> int:
    return int(text.replace(",", ""))


def short_name(signature: str) -> str:
    """ns::(anonymous namespace)::Class::Method(args) -> ns::Class::Method."""
    return signature.replace("(anonymous namespace)::", "").split("(", 1)[0]


def annotate(profile: str, *flags: str) -> list[str]:
    return subprocess.run(["callgrind_annotate", "--inclusive=yes", "--threshold=100", *flags,
                           profile], check=True, text=True, capture_output=True).stdout.splitlines()


def main() -> None:
    p = argparse.ArgumentParser(description=__doc__,
                                formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("bench")
    p.add_argument("bed")
    p.add_argument("--steps", type=int, default=300, help="timed steps of each run (after 200 warm-up)")
    args = p.parse_args()
    if args.steps < 1:
        sys.exit("--steps: must be at least 1")
    for tool in ("valgrind", "callgrind_annotate"):
        if shutil.which(tool) is None:
            sys.exit(f"{tool} not found (Debian package valgrind)")
    with tempfile.TemporaryDirectory() as work:
        profile = os.path.join(work, "callgrind.out")
        run = subprocess.run(["valgrind", "--tool=callgrind", f"--callgrind-out-file={profile}",
                              args.bench, args.bed, str(args.steps), "1", "1"],
                             text=True, capture_output=True)
        if run.returncode != 0:
            sys.exit(f"the bench failed under valgrind:\n{run.stdout}\n{run.stderr}")
        calling = annotate(profile, "--tree=calling")
        flat = annotate(profile)

    # Stepper::Step's callees: inclusive instructions and calls.
    callees = []
    inside = False
    for line in calling:
        if STEP.match(line):
            inside = True
            continue
        if inside:
            if not line.strip():
                break
            m = CALLEE.match(line)
            if m:
                callees.append((short_name(m.group(2)), number(m.group(1)), number(m.group(3))))
    if not callees:
        sys.exit("no callees of seep::core::Stepper::Step in the profile (a build without symbols?)")
    coupled_steps = max((calls for name, _, calls in callees
                         if any(name.endswith("::" + key) for key in FLUID)), default=0)
    if coupled_steps == 0:
        sys.exit("no fluid effect ran: is BENCH seep_coupled_share_bench?")

    def per_step(table: dict) -> dict:
        out = {}
        for name, ir, calls in callees:
            for key, label in table.items():
                if name.endswith("::" + key):
                    out[label] = out.get(label, 0.0) + ir / calls
        return out

    mechanics = per_step(MECHANICS)
    fluid = per_step(FLUID)
    edge_terms = sum(number(m.group(1)) for m in map(FLAT.match, flat)
                     if m and "EdgeTermsBlock" in m.group(2))
    mech_total = sum(mechanics.values())
    fluid_total = sum(fluid.values())

    def listing(parts: dict) -> str:
        return ", ".join(f"{name} {ir / 1e6:.2f}M" for name, ir in parts.items())

    print(f"instructions per DEM step of the settled bed, 1 thread, {coupled_steps} coupled steps "
          "(warm-up included), callgrind:")
    print(f"  mechanics  {mech_total / 1e6:.2f}M: {listing(mechanics)}")
    print(f"  fluid      {fluid_total / 1e6:.2f}M: {listing(fluid)}; of the volume change, the "
          f"edge terms (lens and turn per edge) {edge_terms / coupled_steps / 1e6:.2f}M")
    if mech_total == 0.0:
        sys.exit("no mechanics effect found among Stepper::Step's callees")
    allowance = mech_total / 3.0
    print(f"  fluid / mechanics {fluid_total / mech_total:.2f}; a flow share <= 25 % at the "
          f"mechanics' instructions per cycle allows the fluid {allowance / 1e6:.2f}M "
          f"({100.0 * allowance / fluid_total:.0f} % of what it executes), or needs it "
          f"{fluid_total / allowance:.1f}x the mechanics' instructions per cycle")


if __name__ == "__main__":
    main()
