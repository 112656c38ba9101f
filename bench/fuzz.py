"""The readers under random mutation for minutes: per format, how many inputs escaped, hung or lost their place.

Run ``python bench/fuzz.py`` (``--seconds 300`` per format, ``--formats TML catalogs`` to choose, ``--keep`` to
save each failing input as a regression file in ``tests/fuzz/data/``, ``--seed N`` to repeat a run). The
mutations and the judging are those of the fuzz tests (``tests/fuzz/fuzzing.py``); edits are drawn here with
``random`` instead of hypothesis, which is faster for long runs. Prints the table of issue 17.
"""

from __future__ import annotations

import argparse
import logging
import random
import sys
import time
from collections import Counter
from pathlib import Path

sys.path.insert(0, str(Path(__file__).parents[1] / "tests" / "fuzz"))

import fuzzing  # noqa: E402  (the fuzz tests' harness)


def random_edits(rng: random.Random) -> list[fuzzing.Edit]:
    return [fuzzing.Edit(rng.choice(fuzzing.KINDS), rng.randrange(65536), rng.randrange(65536),
                         rng.randrange(len(fuzzing.PAYLOADS))) for _ in range(rng.randint(1, 4))]


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--seconds", type=float, default=300.0, help="time per format (default 300)")
    parser.add_argument("--formats", nargs="*", default=list(fuzzing.FORMATS), help="formats to fuzz")
    parser.add_argument("--keep", action="store_true", help="save failing inputs in tests/fuzz/data/")
    parser.add_argument("--seed", type=int, default=0)
    args = parser.parse_args()
    logging.disable(logging.CRITICAL)  # the readers' warnings are not what is measured
    rng = random.Random(args.seed)
    rows = []
    examples: dict[str, list[str]] = {}
    with fuzzing.scratch() as folder:
        for name in args.formats:
            fmt = fuzzing.FORMATS[name]
            seeds = [p.read_bytes() for p in fmt.seeds]
            counts: Counter[str] = Counter()
            end = time.monotonic() + args.seconds
            while time.monotonic() < end:
                data = fuzzing.apply(rng.choice(seeds), random_edits(rng))
                verdict = fuzzing.judge(fmt, data, Path(folder))
                counts[verdict.outcome] += 1
                if verdict.outcome != "ok":
                    examples.setdefault(name, []).append(f"{verdict.outcome}: {verdict.detail}")
                    if args.keep:
                        fuzzing.keep(fmt, data, verdict)
            rows.append((name, sum(counts.values()), counts["uncaught"], counts["hang"], counts["unplaced"]))
            print(f"  {name}: {rows[-1][1]} inputs", file=sys.stderr)
    print(f"| {'format':24} | {'inputs':>7} | {'uncaught exceptions':>19} | {'hangs (> 10 s CPU)':>18} "
          f"| {'errors without file:line':>24} |")
    print(f"|{'-' * 26}|{'-' * 9}|{'-' * 21}|{'-' * 20}|{'-' * 26}|")
    for name, total, uncaught, hangs, unplaced in rows:
        print(f"| {name:24} | {total:7} | {uncaught:19} | {hangs:18} | {unplaced:24} |")
    for name, found in examples.items():
        print(f"\n{name}: first of {len(found)} failures")
        for line in found[:5]:
            print(f"  {line}")


if __name__ == "__main__":
    main()
