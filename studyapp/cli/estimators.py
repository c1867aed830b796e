"""``studyapp estimators [--json]``: the estimators, their parameters and inputs."""


def register(sub):
    parser = sub.add_parser("estimators", help="list the velocity estimators and their parameters")
    parser.add_argument("--json", action="store_true", help="print JSON")
    parser.set_defaults(func=run)


def run(args):
    import json

    from studyapp import estimators

    table = [estimators.describe(name) for name in estimators.names()]
    if args.json:
        print(json.dumps(table, indent=2))
        return 0
    print(f"{'name':<12}{'reads':<34}parameters (default)")
    for d in table:
        params = ", ".join(f"{p['name']} ({p['default']!r}{' ' + p['unit'] if p['unit'] else ''})" for p in d["parameters"])
        print(f"{d['name']:<12}{', '.join(d['inputs']):<34}{params or 'none'}")
    return 0
