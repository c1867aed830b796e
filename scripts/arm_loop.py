"""The loop on an ARM Cortex-M7 under qemu against the same loop on this machine (issue 40, "Goal beyond").

    PYTHONPATH=. python scripts/arm_loop.py [--rates 5000,20000] [--seconds 1] [--conditions LVT,KALFOAW]
        [--fmax 1] [--seed 0] [--shift 6] [--keep DIR]

Needs Debian's gcc-arm-none-eabi, libnewlib-arm-none-eabi and qemu-system-arm (scripts/system-deps-arm.txt;
``make arm`` installs them and runs this). For each rate and adjustment condition of
protocols/sinclair2014.toml (its eight estimators with their Table 1 parameters, all stepped every sample,
the condition's one the source):

1. records a sensor stream (position, acceleration, LVT velocity) from the simulated device in the numba
   closed loop (studyapp.model.loop.ClosedLoop at F_max ``--fmax``, gesture "strokes", ``--seed``);
2. runs the C loop on fresh arrays of the same loop, on this machine through ctypes
   (studyapp.device.c_loop.CLoop), and cross-compiled for the Cortex-M7 (firmware/arm, make) in
   ``qemu-system-arm -M mps2-an500`` with semihosting, sample by sample on the recorded stream;
3. compares every sample's outputs (force, source, string and bridge velocity, v_delta, stick, friction and
   the eight estimates) and the arrays after the last sample bit for bit, ARM against x86; and the force,
   string velocity and estimates against the numba loop that recorded the stream (the same sensors give
   the same force: the stream is the loop's own);
4. counts the instructions of each sample on the ARM (qemu -icount shift=S: one instruction, 2^S ns of
   virtual time; the harness's SysTick at the board's 25 MHz measures them, calibrated on a loop of known
   length: firmware/arm/harness.c) and prints the CPU load they imply at 600 MHz;

and prints the sizes (arm-none-eabi-size of the loop's objects; the arrays' bytes at each rate). The table
goes to stdout, progress to stderr. Exit 1 when an ARM output differs from x86's or numba's, 2 on bad input.
"""

import argparse
import os
import shutil
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[1]
FIRMWARE = ROOT / "firmware" / "arm"
PROTOCOL = ROOT / "protocols" / "sinclair2014.toml"
TOOLS = ("make", "arm-none-eabi-gcc", "arm-none-eabi-size", "arm-none-eabi-nm", "arm-none-eabi-objdump",
         "qemu-system-arm")
CLOCK_HZ = 600e6  # the Cortex-M7 clock issue 40 asks about
MAGIC = 0x31414C53  # "SLA1", harness.c
N_OUT = 7  # sl_out's members, harness.c's first columns
OUT_ROWS = ("force", "source_velocity", "string_velocity", "bridge_velocity", "v_delta", "stick", "friction")
N_ARRAYS = 11  # ctl .. nut: the part of Control.arrays the C loop owns (studyapp_loop.h)
RESET_STRING = 0xFFFFFFFF  # an event's "what" that puts the string at rest (harness.c)
EVENT = np.dtype([("k", "<u4"), ("what", "<u4"), ("value", "<f8")])


def say(text):
    print(text, file=sys.stderr, flush=True)


def missing_tools():
    """The programs this needs that are not on PATH (the Debian packages of scripts/system-deps-arm.txt)."""
    return [t for t in TOOLS if shutil.which(t) is None]


def build(build_dir):
    """Cross-compile the harness with the loop (firmware/arm/Makefile); returns the ELF's path."""
    r = subprocess.run(["make", "-s", "-C", str(FIRMWARE), f"BUILD={build_dir}"], capture_output=True, text=True,
                       timeout=600)
    if r.returncode != 0:
        raise RuntimeError(f"make -C firmware/arm failed: {(r.stderr.strip().splitlines() or ['?'])[-1]}")
    return Path(build_dir) / "harness.elf"


def object_sizes(build_dir):
    """{object: (text, data, bss)} for the loop's objects and the ELF (arm-none-eabi-size, Berkeley format)."""
    objs = sorted(str(p) for p in Path(build_dir).glob("studyapp_*.o"))
    r = subprocess.run(["arm-none-eabi-size", *objs], capture_output=True, text=True, check=True)
    sizes = {}
    for line in r.stdout.splitlines()[1:]:
        text, data, bss, _, _, name = line.split()
        sizes[Path(name).stem] = (int(text), int(data), int(bss))
    return sizes


def library_calls(build_dir):
    """The symbols the loop's objects need from outside themselves (arm-none-eabi-nm -u): the toolchain's."""
    objs = [str(p) for p in Path(build_dir).glob("studyapp_*.o")]
    own = subprocess.run(["arm-none-eabi-nm", "--defined-only", *objs], capture_output=True, text=True, check=True)
    need = subprocess.run(["arm-none-eabi-nm", "-u", *objs], capture_output=True, text=True, check=True)
    defined = {line.split()[-1] for line in own.stdout.splitlines() if len(line.split()) == 3}
    return sorted({line.split()[-1] for line in need.stdout.splitlines() if line.strip().startswith("U ")} - defined)


def stack_bound(build_dir):
    """Bytes of stack the loop can take at most: every function's frame added up (-fstack-usage's .su files;
    the loop has no recursion, so no chain of calls takes more)."""
    return sum(int(line.split("\t")[1]) for su in Path(build_dir).glob("studyapp_*.su")
               for line in su.read_text().splitlines() if line.strip())


def conditions():
    """The adjustment task's conditions of protocols/sinclair2014.toml and its estimator parameters."""
    from studyapp.experiment.protocol import load_protocol

    protocol = load_protocol(PROTOCOL)
    return list(protocol.specs["adjustment"].conditions), protocol.estimators


def new_loop(rate, condition, fmax, seed, estimators):
    from studyapp.model.loop import ClosedLoop, LoopConfig

    return ClosedLoop(LoopConfig(rate=rate, estimators=estimators, source=condition, fmax=fmax, seed=seed,
                                 audio=False))


def record(rate, seconds, condition, fmax, seed, estimators):
    """The numba loop's run: its sensor rows (x_m, a_m, v_m) and its outputs (the dict of ClosedLoop.run)."""
    loop = new_loop(rate, condition, fmax, seed, estimators)
    result = loop.run(int(round(seconds * rate)))
    return (result["position"], result["acceleration"], result["velocity_lvt"]), result, loop.names


def write_input(path, arrays, stream, events=()):
    """harness.c's arm_in.bin: the arrays, the control events (k, what, value) in sample order, the stream."""
    ctl, state, lp, ls, kinds, est_s, est_p, sp, ss, bridge, nut = arrays[:N_ARRAYS]
    n = stream[0].shape[0]
    head = np.array([MAGIC, kinds.shape[0], est_s.shape[1], est_p.shape[1], bridge.shape[0], n, len(events), 0],
                    np.uint32)
    with open(path, "wb") as f:
        f.write(head.astype("<u4").tobytes())
        for a in (ctl, state, lp, ls):
            f.write(a.astype("<f8").tobytes())
        f.write(kinds.astype("<i8").tobytes())
        for a in (est_s, est_p, sp, ss, bridge, nut):
            f.write(np.ascontiguousarray(a).astype("<f8").tobytes())
        f.write(np.array(list(events), EVENT).tobytes())
        f.write(np.column_stack(stream).astype("<f8").tobytes())


def run_qemu(elf, workdir, shift, timeout=1800):
    """The harness in qemu-system-arm -M mps2-an500 in ``workdir`` (semihosting's files); its console text."""
    cmd = ["qemu-system-arm", "-M", "mps2-an500", "-nographic", "-monitor", "none", "-serial", "none",
           "-semihosting-config", "enable=on,target=native", "-icount", f"shift={shift},align=off,sleep=off",
           "-kernel", str(elf)]
    r = subprocess.run(cmd, cwd=workdir, capture_output=True, text=True, timeout=timeout)
    if r.returncode != 0:
        raise RuntimeError(f"qemu exit {r.returncode}: {(r.stdout + r.stderr).strip()}")
    return r.stdout


def read_outputs(workdir, n, arrays):
    """(out N_OUT x n, est n_est x n, ticks n, final arrays, meta) from the harness's files."""
    workdir = Path(workdir)
    n_est = arrays[4].shape[0]
    rows = np.fromfile(workdir / "arm_out.bin", "<f8").reshape(n, N_OUT + n_est)
    ticks = np.fromfile(workdir / "arm_ticks.bin", "<u4")
    meta = np.fromfile(workdir / "arm_meta.bin", "<u4")
    flat = np.fromfile(workdir / "arm_state.bin", "<u1")
    final, at = [], 0
    for a in arrays[:N_ARRAYS]:
        final.append(flat[at:at + a.nbytes].view(a.dtype.newbyteorder("<")).reshape(a.shape))
        at += a.nbytes
    return rows[:, :N_OUT].T, rows[:, N_OUT:].T, ticks, final, meta


def x86_outputs(arrays, stream, events=()):
    """The C loop on this machine over the stream, the events applied before their samples as harness.c does."""
    from studyapp.device.c_loop import CLoop

    c = CLoop(arrays)
    n = stream[0].shape[0]
    out, est = np.empty((N_OUT, n)), np.empty((c.n_est, n))
    cuts = sorted({int(k) for k, _, _ in events if k < n} | {0, n})
    for a, b in zip(cuts, cuts[1:]):
        for k, what, value in events:
            if k == a:
                if what == RESET_STRING:
                    c.reset_string()
                else:
                    arrays[0][what] = value
        out[:, a:b], est[:, a:b] = c.run(*(s[a:b] for s in stream), k0=a)
    return out, est, arrays[:N_ARRAYS]


def differing(a, b):
    """(samples whose bits differ, max |a - b|) of two float64 arrays of one shape (column = sample)."""
    a, b = np.atleast_2d(a), np.atleast_2d(b)
    bits = a.view(np.uint64) != b.view(np.uint64)
    with np.errstate(invalid="ignore"):
        diff = np.where(bits, np.abs(a - b), 0.0)
    diff[bits & ~np.isfinite(diff)] = np.inf  # a NaN or an infinity on one side only, or two NaNs' bits
    return int(bits.any(axis=0).sum()), float(diff.max(initial=0.0))


def instructions(ticks, meta):
    """sl_sample's instructions in each sample from its SysTick ticks (harness.c: the calibration, the window's
    own ticks over its empty calls, the empty call's own instructions)."""
    cal_insns, cal_ticks, empty, reps, no_sample = (int(v) for v in meta)
    return (ticks.astype(np.float64) - empty / reps) * cal_insns / cal_ticks + no_sample


def array_bytes(arrays):
    """The RAM of the loop's arrays (bytes), as a firmware holds them: {part: bytes} and the total."""
    ctl, state, lp, ls, kinds, est_s, est_p, sp, ss, bridge, nut = arrays[:N_ARRAYS]
    parts = {"estimator states": est_s.nbytes, "estimator parameters": est_p.nbytes + kinds.nbytes,
             "delay lines": bridge.nbytes + nut.nbytes,
             "control, limits, string": sum(a.nbytes for a in (ctl, state, lp, ls, sp, ss))}
    return {k: int(v) for k, v in parts.items()}


def compare_stream(elf, make_arrays, stream, shift, workdir, events=()):
    """ARM against x86 on one sensor stream and its control events (k, what, value; harness.c), each on fresh
    arrays from ``make_arrays()``: the figures (a dict)."""
    n = stream[0].shape[0]
    events = sorted(events, key=lambda e: e[0])  # stable: events of one sample act in the order given
    arm_arrays = make_arrays()
    write_input(Path(workdir) / "arm_in.bin", arm_arrays, stream, events)
    t0 = time.perf_counter()
    console = run_qemu(elf, workdir, shift)
    qemu_s = time.perf_counter() - t0
    arm_out, arm_est, ticks, arm_final, meta = read_outputs(workdir, n, arm_arrays)
    x86_out, x86_est, x86_final = x86_outputs(make_arrays(), stream, events)
    rows = {name: differing(arm_out[i], x86_out[i]) for i, name in enumerate(OUT_ROWS)}
    rows["estimates"] = differing(arm_est, x86_est)
    final = sum(int(np.count_nonzero(a.reshape(-1).view(np.uint64) != b.reshape(-1).view(np.uint64)))
                for a, b in zip(arm_final, x86_final))
    insn = instructions(ticks, meta)
    return {"n": n, "rows": rows, "final_words_differing": final, "arm_out": arm_out, "arm_est": arm_est,
            "insn_mean": float(insn.mean()), "insn_median": float(np.median(insn)), "insn_max": float(insn.max()),
            "insn_first": float(insn[0]), "insn_max_after_first": float(insn[1:].max(initial=0.0)),
            "meta": [int(v) for v in meta], "console": console, "bytes": array_bytes(arm_arrays), "qemu_s": qemu_s}


def compare_one(elf, rate, seconds, condition, fmax, seed, estimators, shift, workdir):
    """One rate and condition: record the stream, compare ARM with x86, and ARM with the numba loop that recorded it."""
    stream, numba_run, names = record(rate, seconds, condition, fmax, seed, estimators)
    r = compare_stream(elf, lambda: new_loop(rate, condition, fmax, seed, estimators).control.arrays, stream,
                       shift, workdir)
    r["numba"] = {
        "force": differing(r["arm_out"][0], numba_run["force"]),
        "string_velocity": differing(r["arm_out"][2], numba_run["string_velocity"]),
        "estimates": differing(r["arm_est"], numba_run["estimates"]),
    }
    r.update(rate=rate, condition=condition, names=names)
    return r


def load(insn_per_sample, rate, clock=CLOCK_HZ):
    """The share of a ``clock`` Hz core that ``insn_per_sample`` at ``rate`` takes at one instruction a cycle."""
    return insn_per_sample * rate / clock


def report(results, sizes, calls, stack, shift):
    loop_text = sum(v[0] for v in sizes.values())
    loop_data = sum(v[1] for v in sizes.values())
    loop_bss = sum(v[2] for v in sizes.values())
    lines = [
        f"qemu-system-arm -M mps2-an500 (Cortex-M7, fpv5-d16, hard float), -icount shift={shift}; "
        f"loads at {CLOCK_HZ / 1e6:.0f} MHz, one instruction a cycle (optimistic: scripts/arm_insn_mix.py's cycles)",
        "",
        "| rate (Hz) | condition | samples | ARM = x86 (samples differing, max abs diff) | ARM = numba "
        "(force, string, estimates) | instructions/sample: median, max after the first (the first) | load at the "
        "max | arrays (bytes) |",
        "| --- | --- | --- | --- | --- | --- | --- | --- |",
    ]
    for r in results:
        worst = max(r["rows"].values(), key=lambda v: (v[0], v[1]))
        numba = ", ".join(str(v[0]) for v in r["numba"].values())
        lines.append(
            f"| {r['rate']:g} | {r['condition']} | {r['n']} | {worst[0]} ({worst[1]:.3g}); "
            f"final arrays {r['final_words_differing']} | {numba} | {r['insn_median']:.0f}, "
            f"{r['insn_max_after_first']:.0f} ({r['insn_first']:.0f}) | {100 * load(r['insn_max'], r['rate']):.1f} % | "
            f"{sum(r['bytes'].values())} |")
    lines += [
        "",
        *(f"arrays at {r['rate']:g} Hz: " + ", ".join(f"{k} {v} B" for k, v in r["bytes"].items())
          for r in {r["rate"]: r for r in results}.values()),
        f"loop code (arm-none-eabi-size of {len(sizes)} objects, -O2): text {loop_text} B, data {loop_data} B, "
        f"bss {loop_bss} B; stack at most {stack} B (every frame added up)",
        "the loop's calls into the toolchain's libraries: "
        + (", ".join(calls) or "none"),
        f"instruction calibration: {results[0]['meta'][0]} instructions = {results[0]['meta'][1]} ticks "
        f"(expected 2^{shift} ns / 40 ns = {2 ** shift / 40:g} instructions a tick); the window's own "
        f"{results[0]['meta'][2] / results[0]['meta'][3]:.2f} ticks (an empty call's), subtracted",
    ]
    return "\n".join(lines)


def parse_args(argv):
    p = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    p.add_argument("--rates", default="5000,20000", help="loop rates in Hz, comma-separated (default 5000,20000)")
    p.add_argument("--seconds", type=float, default=1.0, help="length of each recorded stream (default 1 s)")
    p.add_argument("--conditions", default="LVT,KALFOAW",
                   help="adjustment conditions (sources), comma-separated, or 'all' (default LVT,KALFOAW)")
    p.add_argument("--fmax", type=float, default=1.0, help="F_max in N (default 1)")
    p.add_argument("--seed", type=int, default=0)
    p.add_argument("--shift", type=int, default=6, help="qemu -icount shift (default 6: 64 ns an instruction)")
    p.add_argument("--keep", help="keep the harness's files here (one folder per run)")
    return p.parse_args(argv)


def check_args(args, allowed):
    from studyapp.estimators.spec import validate_rate
    from studyapp.model import calibration
    from studyapp.model.loop import check_fmax
    from studyapp.model.playable import check_playable

    try:
        rates = [validate_rate(float(r)) for r in args.rates.split(",")]
        for rate in rates:
            check_playable(rate, calibration.F0)
    except Exception as exc:  # noqa: BLE001 (a rate's own message is the one line to show)
        raise ValueError(f"--rates {args.rates!r}: {exc}") from None
    try:
        check_fmax(args.fmax)
    except Exception as exc:  # noqa: BLE001
        raise ValueError(f"--fmax: {exc}") from None
    if args.seed < 0:
        raise ValueError(f"--seed {args.seed}: allowed is a whole number >= 0")
    names = allowed if args.conditions == "all" else args.conditions.split(",")
    bad = [c for c in names if c not in allowed]
    if bad:
        raise ValueError(f"--conditions {bad[0]!r}: allowed are {', '.join(allowed)} or all")
    if not 0.0 < args.seconds <= 60.0:
        raise ValueError(f"--seconds {args.seconds!r}: allowed is a number above 0 and up to 60")
    if not 0 <= args.shift <= 10:
        raise ValueError(f"--shift {args.shift!r}: allowed is 0 to 10")
    return rates, names


def main(argv=None):
    args = parse_args(argv)
    allowed, estimators = conditions()
    try:
        rates, names = check_args(args, allowed)
    except ValueError as exc:
        print(f"arm_loop: {exc}", file=sys.stderr)
        return 2
    missing = missing_tools()
    if missing:
        print(f"arm_loop: missing {', '.join(missing)} (install scripts/system-deps-arm.txt: make arm)",
              file=sys.stderr)
        return 2
    build_dir = ROOT / "build" / "arm"
    say(f"building firmware/arm into {build_dir}")
    elf = build(build_dir)
    results = []
    for rate in rates:
        for condition in names:
            say(f"{rate:g} Hz, {condition}: recording {args.seconds:g} s, then qemu and x86")
            with tempfile.TemporaryDirectory() as tmp:
                workdir = Path(args.keep) / f"{rate:g}-{condition}" if args.keep else Path(tmp)
                os.makedirs(workdir, exist_ok=True)
                r = compare_one(elf, rate, args.seconds, condition, args.fmax, args.seed, estimators, args.shift,
                                workdir)
            say(f"  qemu {r['qemu_s']:.1f} s; {r['insn_median']:.0f} instructions a sample")
            results.append(r)
    print(report(results, object_sizes(build_dir), library_calls(build_dir), stack_bound(build_dir), args.shift))
    equal = all(v[0] == 0 for r in results for v in (*r["rows"].values(), *r["numba"].values())) and \
        all(r["final_words_differing"] == 0 for r in results)
    return 0 if equal else 1


if __name__ == "__main__":
    sys.exit(main())
