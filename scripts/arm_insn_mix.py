"""What the loop's instructions are on a Cortex-M7, and the cycles they bound (issue 40, "Goal beyond").

    PYTHONPATH=. python scripts/arm_insn_mix.py [--rate 5000] [--samples 200] [--condition KALFOAW]

scripts/arm_loop.py counts instructions with qemu's -icount and the harness's SysTick. This counts them a
second, independent way and sorts them: qemu runs the same harness on a recorded stream with one instruction a
translation block and logs every block it executes (-singlestep -d exec,nochain), so the log holds every
executed instruction's address; each address is looked up in arm-none-eabi-objdump's disassembly of the ELF.
The instructions from sl_sample's first until the return to the harness's main are the loop's (the
estimators, the string and the libgcc helpers they call included).

From the mix, two bounds on the cycles of a sample on a real Cortex-M7, from LLVM's scheduling model of the
core (llvm/lib/Target/ARM/ARMScheduleM7.td: dual issue; double-precision arithmetic, loads and stores issue
alone; latencies 4 for a double add, 7 for a multiply, 11 for a multiply-accumulate, 30 for a divide or a
square root; a mispredicted branch costs 4 or more), with code and data in the tightly coupled memories or
the caches (no wait states):

- issue bound (fewest cycles): every instruction that issues alone takes a cycle (a load or store of n
  doubles, n), the others pair up two a cycle, nothing waits for a result;
- serial bound (most cycles, short of memory stalls): nothing overlaps; every instruction takes its full
  latency and every conditional branch is mispredicted.

A real sample lies between. Writes nothing; the table goes to stdout, progress to stderr.
"""

import argparse
import collections
import re
import subprocess
import sys
import tempfile
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent))
import arm_loop  # noqa: E402

MNEMONIC = re.compile(r"^\s+([0-9a-f]+):\s+(?:[0-9a-f]{4} ?)+\s+(\S+)\s*(.*)$")
FUNCTION = re.compile(r"^([0-9a-f]+) <(.+)>:")
# latency (cycles) of double-precision instructions in LLVM's Cortex-M7 model; anything else 1
LATENCY = {"vdiv": 30, "vsqrt": 30, "vmul": 7, "vnmul": 7, "vmla": 11, "vmls": 11, "vnmla": 11, "vnmls": 11,
           "vfma": 11, "vfms": 11}
MISPREDICT = 4
BRANCH = re.compile(r"^(b|bl|bx|blx)(eq|ne|cs|cc|mi|pl|vs|vc|hi|ls|ge|lt|gt|le|hs|lo)?(\.[nw])?$")
CLASSES = ("double divide and square root", "double arithmetic, compare, convert, move",
           "double loads and stores", "FP flags to the core (vmrs)", "branches", "integer and other")


def disassembly(elf):
    """{address: (function, mnemonic, operands)} of every instruction in the ELF."""
    text = subprocess.run(["arm-none-eabi-objdump", "-d", str(elf)], capture_output=True, text=True,
                          check=True).stdout
    table, func = {}, None
    for line in text.splitlines():
        m = FUNCTION.match(line)
        if m:
            func = m.group(2)
            continue
        m = MNEMONIC.match(line)
        if m:
            table[int(m.group(1), 16)] = (func, m.group(2), m.group(3))
    return table


def doubles_moved(operands):
    """How many double registers a vldm/vstm/vpush/vpop moves ({d8-d15} is 8)."""
    count = 0
    for lo, hi in re.findall(r"d(\d+)(?:-d(\d+))?", operands.split("{", 1)[-1]):
        count += int(hi) - int(lo) + 1 if hi else 1
    return count


def classify(mnemonic, operands):
    """(class, issues alone, cycles in the serial bound) of one instruction."""
    base = mnemonic.split(".")[0]
    double = bool(re.search(r"\bd\d", operands))
    if base.startswith(("vldm", "vstm", "vpush", "vpop")):
        n = doubles_moved(operands) if double else 1
        return CLASSES[2], n, 2 * n
    if base in ("vldr", "vstr"):
        return (CLASSES[2], 1, 2) if double else (CLASSES[5], 0, 2)
    if base.startswith("vmrs"):
        return CLASSES[3], 1, 3
    if base in ("vdiv", "vsqrt") and double:
        return CLASSES[0], 1, LATENCY[base]
    if mnemonic.startswith("v") and double:
        return CLASSES[1], 1, LATENCY.get(base, 4)
    branch = BRANCH.match(mnemonic)
    if branch or mnemonic in ("cbz", "cbnz", "tbb", "tbh") or ("{" in operands and "pc}" in operands):
        conditional = mnemonic in ("cbz", "cbnz", "tbb", "tbh") or bool(branch and branch.group(2))
        return CLASSES[4], 0, 1 + (MISPREDICT if conditional else 0)
    return CLASSES[5], 0, 1


def loop_instructions(trace_lines, table, entry):
    """Per executed instruction of the loop: its address (from sl_sample's entry until main runs again)."""
    inside = False
    for line in trace_lines:
        if not line.startswith("Trace"):
            continue
        pc = int(line.split("[", 1)[1].split("/", 2)[1], 16)
        if pc == entry:
            inside = True
        elif inside and table[pc][0] == "main":
            inside = False
        if inside:
            yield pc


def trace(elf, workdir):
    """Run the harness with one instruction a block and every block logged; the log's path."""
    log = Path(workdir) / "trace.log"
    cmd = ["qemu-system-arm", "-M", "mps2-an500", "-nographic", "-monitor", "none", "-serial", "none",
           "-semihosting-config", "enable=on,target=native", "-singlestep", "-d", "exec,nochain", "-D", str(log),
           "-kernel", str(elf)]
    r = subprocess.run(cmd, cwd=workdir, capture_output=True, text=True, timeout=1800)
    if r.returncode != 0:
        raise RuntimeError(f"qemu exit {r.returncode}: {(r.stdout + r.stderr).strip()}")
    return log


def mix(elf, stream, make_arrays, workdir):
    """(samples, {class: count}, {function: count}, issue bound, serial bound), all but samples summed."""
    arm_loop.write_input(Path(workdir) / "arm_in.bin", make_arrays(), stream)
    log = trace(elf, workdir)
    table = disassembly(elf)
    entry = next(a for a, (f, _, _) in table.items() if f == "sl_sample")
    by_class, by_function = collections.Counter(), collections.Counter()
    alone = paired = serial = 0
    with open(log) as lines:
        for pc in loop_instructions(lines, table, entry):
            func, mnemonic, operands = table[pc]
            cls, single, cycles = classify(mnemonic, operands)
            by_class[cls] += 1
            by_function[func] += 1
            alone += single
            paired += 0 if single else 1
            serial += cycles
    log.unlink()
    return stream[0].shape[0], by_class, by_function, alone + paired / 2, serial


def main(argv=None):
    p = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    p.add_argument("--rate", type=float, default=5000.0)
    p.add_argument("--samples", type=int, default=200, help="samples traced (the log takes ~300 kB a sample)")
    p.add_argument("--condition", default="KALFOAW")
    p.add_argument("--fmax", type=float, default=1.0)
    p.add_argument("--seed", type=int, default=0)
    args = p.parse_args(argv)
    allowed, estimators = arm_loop.conditions()
    if args.condition not in allowed:
        print(f"arm_insn_mix: --condition {args.condition!r}: allowed are {', '.join(allowed)}", file=sys.stderr)
        return 2
    if not 1 <= args.samples <= 5000:
        print(f"arm_insn_mix: --samples {args.samples}: allowed is 1 to 5000", file=sys.stderr)
        return 2
    missing = arm_loop.missing_tools()
    if missing:
        print(f"arm_insn_mix: missing {', '.join(missing)} (install scripts/system-deps-arm.txt: make arm)",
              file=sys.stderr)
        return 2
    build_dir = arm_loop.ROOT / "build" / "arm"
    arm_loop.say(f"building firmware/arm into {build_dir}")
    elf = arm_loop.build(build_dir)
    stream, _, _ = arm_loop.record(args.rate, args.samples / args.rate, args.condition, args.fmax, args.seed,
                                   estimators)
    arm_loop.say(f"tracing {stream[0].shape[0]} samples in qemu")
    with tempfile.TemporaryDirectory() as tmp:
        n, by_class, by_function, issue, serial = mix(
            elf, stream, lambda: arm_loop.new_loop(args.rate, args.condition, args.fmax, args.seed,
                                                   estimators).control.arrays, tmp)
    total = sum(by_class.values())
    print(f"{args.rate:g} Hz, {args.condition}, {n} samples traced: {total / n:.1f} instructions a sample")
    print("\n| class | per sample | share |\n| --- | --- | --- |")
    for cls in CLASSES:
        print(f"| {cls} | {by_class[cls] / n:.1f} | {100 * by_class[cls] / total:.1f} % |")
    print("\n| function | per sample |\n| --- | --- |")
    for func, count in by_function.most_common(12):
        print(f"| {func} | {count / n:.1f} |")
    print(f"\ncycles a sample: issue bound {issue / n:.0f}, serial bound {serial / n:.0f} "
          f"({issue / total:.2f} and {serial / total:.2f} cycles an instruction)")
    for rate in (5000.0, 20000.0):
        print(f"load at {rate:g} Hz on {arm_loop.CLOCK_HZ / 1e6:.0f} MHz: {100 * issue / n * rate / arm_loop.CLOCK_HZ:.1f}"
              f" % to {100 * serial / n * rate / arm_loop.CLOCK_HZ:.1f} %")
    return 0


if __name__ == "__main__":
    sys.exit(main())
