"""What the loop's instructions are on a Cortex-M7, and the cycles they bound (issue 40, "Goal beyond").

    PYTHONPATH=. python scripts/arm_insn_mix.py [--rate 5000] [--samples 200] [--condition KALFOAW]

scripts/arm_loop.py counts instructions with qemu's -icount and the harness's SysTick. This counts them a
second, independent way and sorts them: qemu runs the same harness on a recorded stream with one instruction a
translation block and logs every block it executes (-singlestep -d exec,nochain), so the log holds every
executed instruction's address; each address is looked up in arm-none-eabi-objdump's disassembly of the ELF.
The instructions from sl_sample's first until the return to the harness (its ``timed``) are the loop's
(the estimators, the string and the libgcc helpers they call included).

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
CALLERS = ("timed", "main")  # harness.c's functions around sl_sample's call
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
    """(class, how it issues, its issue cycles, its cycles in the serial bound) of one instruction.

    How it issues (LLVM's Cortex-M7 model): "alone" (double loads and stores: one cycle a double, nothing
    beside), "fp" (double arithmetic: both FP ports, so one a cycle, and only first in a pair), "pair"."""
    base = mnemonic.split(".")[0]
    double = bool(re.search(r"\bd\d", operands))
    if base.startswith(("vldm", "vstm", "vpush", "vpop")):
        n = doubles_moved(operands) if double else 1
        return CLASSES[2], "alone", n, 2 * n
    if base in ("vldr", "vstr"):
        return (CLASSES[2], "alone", 1, 2) if double else (CLASSES[5], "pair", 1, 2)
    if base.startswith("vmrs"):
        return CLASSES[3], "pair", 1, 3
    if base in ("vdiv", "vsqrt") and double:
        return CLASSES[0], "fp", 1, LATENCY[base]
    if mnemonic.startswith("v") and double:
        return CLASSES[1], "fp", 1, LATENCY.get(base, 4)
    branch = BRANCH.match(mnemonic)
    if branch or mnemonic in ("cbz", "cbnz", "tbb", "tbh") or ("{" in operands and "pc}" in operands):
        conditional = mnemonic in ("cbz", "cbnz", "tbb", "tbh") or bool(branch and branch.group(2))
        return CLASSES[4], "pair", 1, 1 + (MISPREDICT if conditional else 0)
    return CLASSES[5], "pair", 1, 1


REGISTER = re.compile(r"\b(r1[0-2]|r\d|sp|lr|ip|fp|sl|sb|d\d+|s\d+)\b")
ALIAS = {"ip": "r12", "fp": "r11", "sl": "r10", "sb": "r9"}
CONDITIONS = ("eq", "ne", "cs", "cc", "mi", "pl", "vs", "vc", "hi", "ls", "ge", "lt", "gt", "le", "hs", "lo")
STEMS = {"mov", "mvn", "add", "adc", "sub", "sbc", "rsb", "neg", "and", "orr", "orn", "eor", "bic", "lsl", "lsr",
         "asr", "ror", "mul", "mla", "mls", "umull", "udiv", "sdiv", "clz", "sel", "uadd8", "uxtb", "uxth", "cmp",
         "cmn", "tst", "teq", "ldr", "ldrb", "ldrh", "ldrd", "str", "strb", "strh", "strd", "pop", "push", "ldmia",
         "stmdb", "vmov", "vneg", "vabs", "vadd", "vsub", "vmul", "vnmul", "vdiv", "vsqrt", "vmla", "vmls",
         "vnmla", "vnmls", "vfma", "vfms", "vcvt", "vldr", "vstr", "vpush", "vpop", "vldmia", "vstmia"}


def registers(text):
    """The registers an operand text names; s<n> is half of d<n // 2>, a range {d8-d13} each of its members."""
    out = []
    for lo, hi in re.findall(r"d(\d+)-d(\d+)", text):
        out += [f"d{i}" for i in range(int(lo), int(hi) + 1)]
    for name in REGISTER.findall(re.sub(r"d\d+-d\d+", "", text)):
        name = ALIAS.get(name, name)
        out.append(f"d{int(name[1:]) // 2}" if re.fullmatch(r"s\d+", name) else name)
    return out


UNARY = {"mov", "mvn", "neg", "clz", "uxtb", "uxth", "vmov", "vneg", "vabs", "vsqrt", "vcvt"}


def split_mnemonic(base):
    """(stem, sets the flags, executes conditionally) of a mnemonic without its .size suffix: "movseq" is
    mov, flags, conditional; "lsls" is lsl, flags (not "ls" as a condition): only a known stem counts."""
    for cond in ("",) + CONDITIONS:
        if not base.endswith(cond):
            continue
        stem = base[:len(base) - len(cond)]
        if stem in STEMS:
            return stem, False, bool(cond)
        if stem.endswith("s") and stem[:-1] in STEMS and not stem.startswith("v"):
            return stem[:-1], True, bool(cond)
    return base, False, False


def operands_of(mnemonic, operands):
    """(destinations, sources, latency) of one instruction for the in-order model (LLVM's latencies)."""
    base = mnemonic.split(".")[0]
    regs = registers(operands.split("@")[0])
    double = any(r.startswith("d") for r in regs)
    if base.startswith("vmrs"):
        return ["apsr"], ["fpscr"], 1
    if base.startswith("vcmp"):
        return ["fpscr"], regs, 4
    if base.startswith("vsel"):  # reads the flags, writes its destination whatever they are
        return regs[:1], regs[1:] + ["apsr"], 4
    if BRANCH.match(mnemonic) or base in ("cbz", "cbnz", "tbb", "tbh") or base.startswith("it"):
        return [], regs + ["apsr"], 1
    stem, flags, conditional = split_mnemonic(base)
    if stem in ("cmp", "cmn", "tst", "teq"):
        return ["apsr"], regs, 1
    if stem in ("str", "strd", "strb", "strh", "vstr", "push", "vpush", "stmdb", "vstmia"):
        return [], regs, 1
    if stem in ("ldr", "ldrb", "ldrh", "ldrd", "vldr", "pop", "vpop", "ldmia", "vldmia"):
        if "{" in operands:
            listed = registers(operands.split("{", 1)[1])
            dest, src = listed, [r for r in regs if r not in listed]
        else:
            two = stem == "ldrd"
            dest, src = regs[:1 + two], regs[1 + two:]
        return dest, src + (dest + ["apsr"] if conditional else []), 2
    dest, src = regs[:1], regs[1:]
    if base.startswith("vmov") and len(regs) == 3:  # a double to or from two core registers
        dest, src = (regs[:1], regs[1:]) if regs[0].startswith("d") else (regs[:2], regs[2:])
        return dest, src, 3
    accumulates = stem in ("vmla", "vmls", "vnmla", "vnmls", "vfma", "vfms")
    two_operand = operands.count(",") == 1 and stem not in UNARY  # "subs r3, #1": r3 = r3 - 1
    if conditional or accumulates or two_operand:
        src = src + dest + (["apsr"] if conditional else [])
    if flags:
        dest = dest + ["apsr"]
    if mnemonic.startswith("v") and double:
        return dest, src, LATENCY.get(stem, 4)
    return dest, src, 2 if stem in ("mul", "mla", "mls", "umull") else 1


def in_order_cycles(instructions):
    """Cycles of an in-order, dual-issue core on the executed instructions, after LLVM's Cortex-M7 model.

    Each instruction issues, in order, once its sources are ready (their producers' latencies: LATENCY for
    double multiplies, divides and roots, 4 for other double arithmetic and compares, 2 for loads, 3 for a
    move between the register files, 1 else); two a cycle at most, a double-arithmetic one only first of
    the two, a double load or store alone (a cycle a double); every branch predicted right. An estimate, not
    a bound: the M7's forwarding paths, its branch predictor and its memories are not modelled."""
    ready = collections.defaultdict(int)
    cycle = slot = 0  # the cycle being filled and how many instructions it has
    for mnemonic, operands in instructions:
        dest, src, latency = operands_of(mnemonic, operands)
        _, issue, n, _ = classify(mnemonic, operands)
        earliest = max([ready[r] for r in src], default=0)
        if not (slot == 1 and issue == "pair" and earliest <= cycle):
            cycle = max(cycle + (1 if slot else 0), earliest)
            slot = 0
        for r in dest:
            ready[r] = cycle + latency
        if issue == "alone":
            cycle, slot = cycle + n, 0
        else:
            slot += 1
    return cycle + (1 if slot else 0)


def loop_instructions(trace_lines, table, entry):
    """Per executed instruction of the loop: its address (from sl_sample's entry until the harness runs again)."""
    inside = False
    for line in trace_lines:
        if not line.startswith("Trace"):
            continue
        pc = int(line.split("[", 1)[1].split("/", 2)[1], 16)
        if pc == entry:
            inside = True
        elif inside and table[pc][0] in CALLERS:
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


def mix(elf, stream, make_arrays, workdir, model=True):
    """(samples, {class: count}, {function: count}, issue bound, serial bound, in-order model's cycles or None
    when not ``model``), all but samples summed over the samples."""
    arm_loop.write_input(Path(workdir) / "arm_in.bin", make_arrays(), stream)
    log = trace(elf, workdir)
    table = disassembly(elf)
    entry = next(a for a, (f, _, _) in table.items() if f == "sl_sample")
    by_class, by_function = collections.Counter(), collections.Counter()
    alone = fp = paired = serial = 0
    executed = []
    with open(log) as lines:
        for pc in loop_instructions(lines, table, entry):
            func, mnemonic, operands = table[pc]
            if model:
                executed.append((mnemonic, operands))
            cls, issue, n, cycles = classify(mnemonic, operands)
            by_class[cls] += 1
            by_function[func] += 1
            alone += n if issue == "alone" else 0
            fp += issue == "fp"
            paired += issue == "pair"
            serial += cycles
    log.unlink()
    issue_bound = alone + max(fp, (fp + paired) / 2)
    return stream[0].shape[0], by_class, by_function, issue_bound, serial, in_order_cycles(executed) if model else None


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
        n, by_class, by_function, issue, serial, model = mix(
            elf, stream, lambda: arm_loop.new_loop(args.rate, args.condition, args.fmax, args.seed,
                                                   estimators).control.arrays, tmp)
    total = sum(by_class.values())
    print(f"{args.rate:g} Hz, {args.condition}, {n} samples traced: {total / n:.1f} instructions a sample")
    print("\n| class | per sample | share |\n| --- | --- | --- |")
    for cls in CLASSES:
        print(f"| {cls} | {by_class[cls] / n:.1f} | {100 * by_class[cls] / total:.1f} % |")
    print("\n| function | per sample |\n| --- | --- |")
    for func, count in by_function.most_common():
        print(f"| {func} | {count / n:.1f} |")
    print("\n| cycles a sample | cycles | per instruction | load at 5 kHz | at 20 kHz |")
    print("| --- | --- | --- | --- | --- |")
    for name, cycles in (("issue bound", issue), ("in-order model", model), ("serial bound", serial)):
        loads = [100 * cycles / n * rate / arm_loop.CLOCK_HZ for rate in (5000.0, 20000.0)]
        print(f"| {name} | {cycles / n:.0f} | {cycles / total:.2f} | {loads[0]:.1f} % | {loads[1]:.1f} % |")
    print(f"(loads on a {arm_loop.CLOCK_HZ / 1e6:.0f} MHz core, for the mean sample traced)")
    return 0


if __name__ == "__main__":
    sys.exit(main())
