"""``studyapp demo``: every estimator on a stick-slip signal, with error and delay.

A headless look at what exists: a synthetic stick-slip position signal with
the paper's LVDT noise (``studyapp.synthetic``) goes through every estimator;
each is scored against the true velocity with the paper's metric (delay D at
the peak cross-correlation, error E the RMSE after removing D; eqs. 22-24),
D by ``--delay`` (``evaluation/metric.py``). The synthetic ripple is exactly
periodic, and a delay cannot be told from itself plus a period (the normalised
correlation, unlike eq. 22's, has no pull towards short lags to pick one), so
the search runs over lags shorter than half the stick-slip period. An estimator whose Table 1
defaults cannot exist at ``--rate`` (COMP2's 2,254 Hz high-pass below 4.6 kHz)
is listed as not available, with the reason.
"""

from studyapp.cli import delay_option, number_options

F0 = 110.0  # Hz, the synthetic signal's stick-slip frequency


def register(sub):
    parser = sub.add_parser("demo", help="headless demo: every estimator on a stick-slip signal")
    parser.add_argument("--rate", type=float, default=5000.0, help="sample rate in Hz (default 5000)")
    parser.add_argument("--seconds", type=float, default=2.0, help="signal length (default 2 s)")
    parser.add_argument("--seed", type=number_options.seed, default=0, help="noise seed (default 0)")
    delay_option.add(parser)
    parser.set_defaults(func=run)


def run(args):
    from studyapp import estimators
    from studyapp.errors import ParameterError
    from studyapp.estimators.registry import spec
    from studyapp.estimators.spec import validate_rate
    from studyapp.evaluation import delay_and_error
    from studyapp.synthetic import stick_slip

    rate = validate_rate(args.rate, "--rate")
    if not 0.1 <= args.seconds <= 600:
        raise ParameterError(f"--seconds {args.seconds:g}: allowed is 0.1 to 600")
    sig = stick_slip(rate, args.seconds, f0=F0, seed=args.seed)
    ref = sig["velocity_true"]
    max_lag = max(1, int(rate / F0 / 2))
    print(f"stick-slip signal: {args.seconds:g} s at {rate:g} Hz, LVDT noise 15 um RMS, 16 bit over 2.2 cm")
    print(f"reference: true velocity; D = delay (samples, {args.delay} method, |D| <= {max_lag}), "
          f"E = delay-corrected RMSE (mm/s)")
    print(f"{'estimator':<12}{'D':>6}{'E':>12}")
    unavailable = {name: spec(name).not_available(rate) for name in estimators.names()}
    bank = estimators.Bank(rate, [name for name, reason in unavailable.items() if reason is None])
    out = bank.process(sig["position"], sig["acceleration"], sig["velocity_lvt"])
    rows = []
    for name, estimate in zip(bank.names, out):
        delay, error = delay_and_error(ref, estimate, max_lag, args.delay)
        rows.append((error, name, delay))
        print(f"{name:<12}{delay:>6d}{error * 1e3:>12.3f}")
    for name, reason in unavailable.items():
        if reason is not None:
            print(f"{name:<12}{reason}")
    best = min(rows)
    print(f"lowest error: {best[1]} ({best[0] * 1e3:.3f} mm/s)")
    return 0
