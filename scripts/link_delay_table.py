"""The link's delay against the paper's effect: breakdown F_max over latency, packets and jitter (issue 29).

    PYTHONPATH=. python scripts/link_delay_table.py [--seeds 5] [--jobs 2] [--rows latency,packet]
        [--out docs] [--plot-only]

For the adjustment task's conditions of protocols/sinclair2014.toml (eight
estimators with their Table 1 parameters, and LVT) and TRUE, the breakdown
F_max (studyapp.model.breakdown: bowing ``strokes`` at 5 kHz, 5 s trials,
judged against TRUE on an ideal link) with the simulated device behind each
link (studyapp.model.link), over seeds 0..N-1, median, min and max:

- ``latency`` rows: a fixed latency of 0, 0.2, 0.4, 1 and 2 ms (0-10 samples);
- ``packet`` rows: 1 ms packets (5 samples; the device holds each packet's
  answer, the force from its newest sample), with no latency, with 1 ms, and
  with 1 ms plus 0-1 ms of jitter; and the other way to answer a packet, one
  force per sample applied a packet later, which is a pure latency of P - 1
  = 4 samples (0.8 ms).

The device-loop rows (``--device emulator --loop device``): the same
searches with each trial on a device that runs the loop itself
(studyapp/device/emulated_loop.py: ``studyapp device-emulator --loop device
--lockstep`` in its own process over a pty, 5 kHz, telemetry packets of 10
samples; the host's shadow of the loop, its settings and keep-alive
``--late`` samples after each full packet: 1, 5 and 20 by default), for the
conditions but TRUE (a device has no true velocity; the reference stays the
model's TRUE, the handle's velocity judged is the device's LVT). Each trial
starts its own emulator, so a search costs about a minute of two cores:
``--sources`` runs a subset (LVT must be in it). Writes
``OUT/device_loop_table.csv`` and prints its table.

Writes ``OUT/link_delay_table.csv`` (one row per link and source, each seed's
value) and ``OUT/link_delay.png`` (breakdown F_max against latency), prints
the Markdown tables of docs/devices.md, and shows each search's progress with
an estimate of the time left on stderr. ``--plot-only`` redraws the plot and
the tables from the CSV. The searches run in ``--jobs`` processes, a seed's
searches together (the TRUE reference runs are cached per process).
"""

import argparse
import csv
import datetime
import math
import sys
import time
from concurrent.futures import ProcessPoolExecutor, as_completed
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
PROTOCOL = ROOT / "protocols" / "sinclair2014.toml"
RATE = 5000.0
LATENCIES = (0.0, 0.0002, 0.0004, 0.001, 0.002)  # s
PACKET = 0.001  # s
PACKET_LINKS = ((0.0, PACKET, 0.0), (0.001, PACKET, 0.0), (0.001, PACKET, 0.001), (0.0008, 0.0, 0.0))
FIELDS = ("latency", "packet", "jitter", "source", "fmax_median", "fmax_min", "fmax_max", "fmax_per_seed")


def conditions():
    """(sources, estimator params): the protocol's adjustment conditions, then TRUE."""
    from studyapp.experiment.protocol import load_protocol

    protocol = load_protocol(PROTOCOL)
    return list(protocol.specs["adjustment"].conditions) + ["TRUE"], protocol.estimators


def links(rows):
    out = []
    if "latency" in rows:
        out += [(lat, 0.0, 0.0) for lat in LATENCIES]
    if "packet" in rows:
        out += list(PACKET_LINKS)
    return out


def search(seed, link, source, params):
    """One breakdown search: (seed, link, source, F_max, CPU seconds)."""
    from studyapp.model.breakdown import breakdown_fmax
    from studyapp.model.link import LinkSpec

    start = time.process_time()
    own = {} if source in ("LVT", "TRUE") else {source: params.get(source, {})}
    value = breakdown_fmax(source, rate=RATE, seed=seed, estimators=own,
                           link=LinkSpec(latency=link[0], packet=link[1], jitter=link[2]))
    return seed, link, source, value, time.process_time() - start


def device_search(seed, late, source):
    """One breakdown search on the emulator's device loop: (seed, late, source, F_max, host CPU seconds)."""
    from studyapp.device.emulated_loop import factory
    from studyapp.model.breakdown import breakdown_fmax

    start = time.process_time()
    value = breakdown_fmax(source, rate=RATE, seed=seed, make_loop=factory(late))
    return seed, late, source, value, time.process_time() - start


def measure_device_loop(seeds, lates, sources, jobs):
    """{(late, source): [F_max per seed]} on the emulator's device loop (the searches in ``jobs`` processes)."""
    results = {}
    tasks = [(seed, late, source) for late in lates for source in sources for seed in range(seeds)]
    t0 = time.monotonic()
    with ProcessPoolExecutor(jobs) as pool:
        futures = [pool.submit(device_search, *task) for task in tasks]
        for done, future in enumerate(as_completed(futures), 1):
            seed, late, source, value, _ = future.result()
            results.setdefault((late, source), {})[seed] = value
            wall = time.monotonic() - t0
            print(f"link_delay_table: device loop {done}/{len(tasks)} searches, {wall / 60:.1f} min so far, about "
                  f"{wall / done * (len(tasks) - done) / 60:.1f} min left", file=sys.stderr, flush=True)
    return [{"late": late, **row((0.0, 0.0, 0.0), source, [results[(late, source)][s] for s in range(seeds)])}
            for late in lates for source in sources]


DEVICE_FIELDS = ("late", "source", "fmax_median", "fmax_min", "fmax_max", "fmax_per_seed")


def write_device_csv(path, rows):
    with open(path, "w", newline="", encoding="utf-8") as f:
        writer = csv.writer(f, lineterminator="\n")
        writer.writerow(DEVICE_FIELDS)
        for r in rows:
            writer.writerow([r["late"], r["source"]] + [repr(r[k]) for k in DEVICE_FIELDS[2:5]]
                            + [";".join(repr(v) for v in r["fmax_per_seed"])])


def device_table(rows):
    """The device-loop table: per lateness, every source's median (min-max), LVT over the best estimator."""
    lates = list(dict.fromkeys(r["late"] for r in rows))
    sources = list(dict.fromkeys(r["source"] for r in rows))
    order = ["LVT"] + [s for s in sources if s != "LVT"]
    lines = ["| the host's answers | " + " | ".join(order) + " | LVT / best (best) | seeds: LVT / best |",
             "|" + " --- |" * (len(order) + 3)]
    for late in lates:
        by = {r["source"]: r for r in rows if r["late"] == late}
        ratio, best = margin({s: by[s]["fmax_median"] for s in by})
        per_seed = [lvt / max(by[s]["fmax_per_seed"][i] for s in by if s != "LVT")
                    for i, lvt in enumerate(by["LVT"]["fmax_per_seed"])]
        cells = [f"{number(by[s]['fmax_median'])} ({number(by[s]['fmax_min'])}-{number(by[s]['fmax_max'])})"
                 for s in order]
        lines.append(f"| {late} sample{'s' * (late > 1)} late | " + " | ".join(cells) + f" | {ratio:.2f} ({best}) | "
                     + ", ".join(f"{v:.2f}" for v in per_seed) + " |")
    return "\n".join(lines) + "\n"


def seed_batch(seed, link_list, sources, params):
    return [search(seed, link, source, params) for link in link_list for source in sources]


def measure(seeds, rows, jobs):
    sources, params = conditions()
    link_list = links(rows)
    total = seeds * len(link_list) * len(sources)
    results = {}
    cpu = 0.0
    done = 0
    t0 = time.monotonic()
    # one task per (seed, link): a seed's TRUE references stay cached in the process that runs most of them
    with ProcessPoolExecutor(jobs) as pool:
        futures = [pool.submit(seed_batch, seed, [link], sources, params)
                   for seed in range(seeds) for link in link_list]
        for future in as_completed(futures):
            for seed, link, source, value, seconds in future.result():
                results[(link, source, seed)] = value
                cpu += seconds
                done += 1
            wall = time.monotonic() - t0
            left = wall / done * (total - done)
            print(f"link_delay_table: {done}/{total} searches, {cpu / done:.1f} s CPU each, "
                  f"{wall / 60:.1f} min so far, about {left / 60:.1f} min left", file=sys.stderr, flush=True)
    rows_out = []
    for link in link_list:
        for source in sources:
            values = [results[(link, source, seed)] for seed in range(seeds)]
            rows_out.append(row(link, source, values))
    return rows_out, cpu


def row(link, source, values):
    import numpy as np

    return {"latency": link[0], "packet": link[1], "jitter": link[2], "source": source,
            "fmax_median": float(np.median(values)), "fmax_min": min(values), "fmax_max": max(values),
            "fmax_per_seed": values}


def write_csv(path, rows):
    with open(path, "w", newline="", encoding="utf-8") as f:
        writer = csv.writer(f, lineterminator="\n")
        writer.writerow(FIELDS)
        for r in rows:
            writer.writerow([repr(r[k]) for k in FIELDS[:3]] + [r["source"]]
                            + [repr(r[k]) for k in FIELDS[4:7]] + [";".join(repr(v) for v in r["fmax_per_seed"])])


def read_csv(path):
    rows = []
    with open(path, encoding="utf-8") as f:
        for r in csv.DictReader(f):
            rows.append({"latency": float(r["latency"]), "packet": float(r["packet"]), "jitter": float(r["jitter"]),
                         "source": r["source"], "fmax_median": float(r["fmax_median"]),
                         "fmax_min": float(r["fmax_min"]), "fmax_max": float(r["fmax_max"]),
                         "fmax_per_seed": [float(v) for v in r["fmax_per_seed"].split(";")]})
    return rows


def margin(by_source):
    """LVT over the best estimator (the largest median but LVT's and TRUE's), and that estimator."""
    others = {s: v for s, v in by_source.items() if s not in ("LVT", "TRUE")}
    best = max(others, key=others.get)
    return by_source["LVT"] / others[best], best


def number(v):
    return "> 200" if math.isinf(v) else f"{v:.3g}"


def link_label(link):
    latency, packet, jitter = link
    if packet == 0 and jitter == 0:
        return "0" if latency == 0 else f"{latency * 1000:g} ms ({round(latency * RATE)} sample{'s' * (latency * RATE > 1.5)})"
    words = [f"{packet * 1000:g} ms packets" if packet else "per-sample forces"]
    words.append(f"+ {latency * 1000:g} ms latency" if latency else "no latency")
    if jitter:
        words.append(f"+ 0-{jitter * 1000:g} ms jitter")
    return ", ".join(words) if packet else f"{latency * 1000:g} ms latency (one force per sample, a packet late)"


def tables(rows):
    """The Markdown tables: every source per link, medians (min-max over seeds), and LVT's margin."""
    link_list = list(dict.fromkeys((r["latency"], r["packet"], r["jitter"]) for r in rows))
    sources = list(dict.fromkeys(r["source"] for r in rows))
    order = ["TRUE", "LVT"] + [s for s in sources if s not in ("TRUE", "LVT")]
    head = "| link | " + " | ".join(order) + " | LVT / LOWPASS | LVT / best (best) |"
    lines = [head, "|" + " --- |" * (len(order) + 3)]
    for link in link_list:
        by = {r["source"]: r for r in rows if (r["latency"], r["packet"], r["jitter"]) == link}
        ratio, best = margin({s: by[s]["fmax_median"] for s in by})
        cells = [f"{number(by[s]['fmax_median'])} ({number(by[s]['fmax_min'])}-{number(by[s]['fmax_max'])})"
                 for s in order]
        lowpass = by["LVT"]["fmax_median"] / by["LOWPASS"]["fmax_median"]
        lines.append(f"| {link_label(link)} | " + " | ".join(cells) + f" | {lowpass:.2f} | {ratio:.2f} ({best}) |")
    return "\n".join(lines) + "\n"


def plot(rows, path):
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    pure = [r for r in rows if r["packet"] == 0 and r["jitter"] == 0 and r["latency"] in LATENCIES]
    sources = list(dict.fromkeys(r["source"] for r in pure))
    fig, ax = plt.subplots(figsize=(8, 5.2), dpi=110)
    styles = {"TRUE": dict(color="black", lw=2.2), "LVT": dict(color="tab:red", lw=2.4)}
    others = iter(["tab:blue", "tab:orange", "tab:green", "tab:purple", "tab:brown", "tab:pink", "tab:gray",
                   "tab:olive", "tab:cyan"])
    for source in sources:
        rs = sorted((r for r in pure if r["source"] == source), key=lambda r: r["latency"])
        x = [r["latency"] * 1000 for r in rs]
        y = [min(r["fmax_median"], 200.0) for r in rs]
        style = styles.get(source) or dict(color=next(others), lw=1.1, ls="--")
        ax.plot(x, y, marker="o", ms=3.5, label=source, **style)
        if source in styles:
            ax.fill_between(x, [min(r["fmax_min"], 200.0) for r in rs], [min(r["fmax_max"], 200.0) for r in rs],
                            color=style["color"], alpha=0.12, lw=0)
    ax.set_yscale("log")
    ticks = [2, 3, 4, 5, 6, 8, 10, 15, 20, 25]
    ax.set_yticks(ticks, [f"{t:g}" for t in ticks])
    ax.minorticks_off()
    ax.set_xlabel("link latency (ms; one sample = 0.2 ms at 5 kHz)")
    ax.set_ylabel("breakdown F_max (N), median over seeds")
    ax.set_title("Bowing breakdown against the link's latency (5 kHz, strokes)")
    ax.grid(True, which="both", alpha=0.3)
    ax.legend(ncol=2, fontsize=8, loc="upper right")
    fig.tight_layout()
    fig.savefig(path)
    plt.close(fig)


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--seeds", type=int, default=5, help="seeds 0..N-1 (default 5)")
    parser.add_argument("--jobs", type=int, default=2, help="processes (default 2)")
    parser.add_argument("--rows", default="latency,packet", help="latency, packet or both (default both)")
    parser.add_argument("--out", default=str(ROOT / "docs"), help="folder for the CSV and the PNG (default docs)")
    parser.add_argument("--plot-only", action="store_true", help="redraw the plot and tables from the CSV")
    parser.add_argument("--device", default="model", metavar="model|emulator",
                        help="model: the simulated device behind the model's link (default); emulator: the device "
                             "emulator in its own process (with --loop device)")
    parser.add_argument("--loop", default="host", metavar="host|device",
                        help="with --device emulator: device, the loop on the device (protocol 2)")
    parser.add_argument("--late", default="1,5,20", metavar="SAMPLES,...",
                        help="with --loop device: how late the host's answers are, in samples (default 1,5,20)")
    parser.add_argument("--sources", default=None, metavar="NAME,...",
                        help="with --loop device: the sources to search (default the adjustment conditions)")
    args = parser.parse_args(argv)
    out = Path(args.out)
    if args.device != "model":
        return device_main(args, out)
    csv_path, png_path = out / "link_delay_table.csv", out / "link_delay.png"
    if args.plot_only:
        rows = read_csv(csv_path)
    else:
        rows, cpu = measure(args.seeds, set(args.rows.split(",")), args.jobs)
        write_csv(csv_path, rows)
        print(f"link_delay_table: {cpu / 60:.1f} min CPU in all", file=sys.stderr)
    plot(rows, png_path)
    print(f"Generated on {datetime.date.today().isoformat()} by `PYTHONPATH=. python scripts/link_delay_table.py "
          f"--seeds {args.seeds} --rows {args.rows}`.\n")
    sys.stdout.write(tables(rows))
    print(f"wrote {csv_path} and {png_path}", file=sys.stderr)
    return 0


def device_main(args, out):
    if (args.device, args.loop) != ("emulator", "device"):
        print(f"link_delay_table: --device {args.device} --loop {args.loop}: allowed is --device emulator --loop "
              "device (the host loop's figures are the model's rows)", file=sys.stderr)
        return 2
    sources = args.sources.split(",") if args.sources else [s for s in conditions()[0] if s != "TRUE"]
    if "LVT" not in sources or len(sources) < 2:
        print(f"link_delay_table: --sources {args.sources}: allowed is LVT and at least one estimator",
              file=sys.stderr)
        return 2
    lates = [int(v) for v in args.late.split(",")]
    rows = measure_device_loop(args.seeds, lates, sources, args.jobs)
    path = out / "device_loop_table.csv"
    write_device_csv(path, rows)
    words = f" --sources {args.sources}" if args.sources else ""
    print(f"Generated on {datetime.date.today().isoformat()} by `PYTHONPATH=. python scripts/link_delay_table.py "
          f"--device emulator --loop device --seeds {args.seeds} --late {args.late}{words} --jobs {args.jobs}`.\n")
    sys.stdout.write(device_table(rows))
    print(f"wrote {path}", file=sys.stderr)
    return 0


if __name__ == "__main__":
    sys.exit(main())
