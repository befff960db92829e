"""Same-run regression check: reads two files of `BENCH <name> <key>=<value>` (or
`BENCH <name> <value>`) lines — the base tree's and this tree's, measured in the same
run — and prints, per line, base, new, the ratio new/base and a flag when this tree is
more than the threshold (default 10 %) worse. Lines whose name ends in `_per_s` (or
contains `speedup` or `_over_`, a ratio of a slower path's time over a faster one's) are
better when higher; all others (times) when lower. Each side's
value is its best over the runs in its file.
Usage: python3 bench/regression.py BASE.log NEW.log [--threshold 0.10]
Exit status 0 always (a report, not a gate); the last line counts the flags."""
import sys


def higher_is_better(name):
    return name.endswith("_per_s") or "speedup" in name or "_over_" in name


def read(path):
    """Per line name, the best value over the runs in the file (the minimum of a time,
    the maximum of a rate): the least noisy estimate on a loaded machine."""
    vals = {}
    for line in open(path, encoding="utf-8", errors="replace"):
        parts = line.split()
        if len(parts) < 3 or parts[0] != "BENCH":
            continue
        raw = parts[2].split("=", 1)[1] if "=" in parts[2] else parts[2]
        try:
            v = float(raw)
        except ValueError:
            continue
        name = parts[1]
        best = max if higher_is_better(name) else min
        vals[name] = best(vals[name], v) if name in vals else v
    return vals


def main(argv):
    args = [a for a in argv[1:] if not a.startswith("--")]
    threshold = 0.10
    if "--threshold" in argv:
        threshold = float(argv[argv.index("--threshold") + 1])
        args = [a for a in args if a != argv[argv.index("--threshold") + 1]]
    base, new = read(args[0]), read(args[1])
    flagged = 0
    print(f"{'line':44} {'base':>12} {'new':>12} {'new/base':>9}  flag")
    for name in sorted(set(base) | set(new)):
        b, n = base.get(name), new.get(name)
        if b is None or n is None:
            print(f"{name:44} {'-' if b is None else f'{b:.4g}':>12} "
                  f"{'-' if n is None else f'{n:.4g}':>12} {'-':>9}  only one side")
            continue
        ratio = n / b if b else float("inf") if n else 1.0
        worse = (ratio < 1 - threshold) if higher_is_better(name) else (ratio > 1 + threshold)
        flagged += worse
        print(f"{name:44} {b:>12.4g} {n:>12.4g} {ratio:>9.3f}  {'REGRESSION' if worse else ''}")
    print(f"{flagged} line(s) more than {threshold:.0%} worse than the base")


if __name__ == "__main__":
    main(sys.argv)
