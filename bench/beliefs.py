"""Belief memory speed: queries per second at 1,000, 10,000 and 100,000 objects.

Run ``python bench/beliefs.py`` (``--sizes 1000 10000`` to choose sizes). It loads,
for each object oK: object(oK, class_{K mod 6}), code(oK, K), color(oK, <7 colors>),
position(oK, (x, y, z)) and visible(oK) when K mod 5 = 0, then times each query
of issue 2 and prints one row per figure with the target for N = 100,000.
"""

from __future__ import annotations

import argparse
import time

from aeroexec.beliefs import BeliefMemory, Struct, parse_expression

COLORS = ("red", "green", "blue", "yellow", "white", "black", "orange")


def facts_text(n: int) -> list[str]:
    out = []
    for k in range(n):
        o = f"o{k}"
        out.append(f"object({o}, class_{k % 6})")
        out.append(f"code({o}, {k})")
        out.append(f"color({o}, {COLORS[k % 7]})")
        out.append(f"position({o}, ({k * 0.5}, {k % 100 * 1.0}, {k % 7 * 0.25}))")
        if k % 5 == 0:
            out.append(f"visible({o})")
    return out


def facts_terms(n: int) -> list[Struct]:
    out = []
    for k in range(n):
        o = f"o{k}"
        out.append(Struct("object", (o, f"class_{k % 6}")))
        out.append(Struct("code", (o, k)))
        out.append(Struct("color", (o, COLORS[k % 7])))
        out.append(Struct("position", (o, (k * 0.5, k % 100 * 1.0, k % 7 * 0.25))))
        if k % 5 == 0:
            out.append(Struct("visible", (o,)))
    return out


def rate(fn, budget: float = 0.4) -> float:
    """Calls per second of ``fn`` over about ``budget`` seconds (best of three rounds)."""
    calls = 1
    while True:
        start = time.perf_counter()
        for _ in range(calls):
            fn()
        spent = time.perf_counter() - start
        if spent > budget / 4:
            break
        calls *= 4
    best = 0.0
    for _ in range(3):
        start = time.perf_counter()
        for _ in range(calls):
            fn()
        best = max(best, calls / (time.perf_counter() - start))
    return best


def measure(n: int) -> dict[str, float]:
    results: dict[str, float] = {}
    texts = facts_text(n)
    memory = BeliefMemory()
    start = time.perf_counter()
    for text in texts:
        memory.add(text)
    results["load from text (facts/s)"] = len(texts) / (time.perf_counter() - start)
    terms = facts_terms(n)
    memory = BeliefMemory()
    start = time.perf_counter()
    for belief in terms:
        memory.add(belief)
    results["load from terms (facts/s)"] = len(terms) / (time.perf_counter() - start)

    k = min(500, n - 1)
    j = 777 if n > 777 else 3 + 6 * ((n - 1) // 12)
    queries = {
        "(a) code(o500, 500)": (memory.query, f"code(o{k}, {k})"),
        "(b) color(o500, ?C)": (memory.query, f"color(o{k}, ?C)"),
        "(c) object(?X, class_3), code(?X, 777)": (memory.query, f"object(?X, class_3), code(?X, {j})"),
        "(d) all: object(?X, class_3), visible(?X), color(?X, red)": (
            memory.query_all,
            "object(?X, class_3), visible(?X), color(?X, red)",
        ),
        "(e) all: code(?X, ?C), ?C > N-5": (memory.query_all, f"code(?X, ?C), ?C > {n - 5}"),
    }
    for label, (method, text) in queries.items():
        assert method(text) not in (None, []), f"{text} found nothing"
        results[label] = rate(lambda m=method, t=text: m(t))

    updates = [Struct("position", ("o1", (i * 0.1, 2.0, 1.5))) for i in range(10_000)]
    start = time.perf_counter()
    for belief in updates:
        memory.add(belief)
    results["(f) replace position(o1, ...) (updates/s)"] = len(updates) / (
        time.perf_counter() - start
    )
    assert len(memory.query_all("position(o1, ?P)")) == 1
    parse_expression.cache_clear()
    return results


TARGET_SIZE = 100_000  # the size the targets are for
TARGETS = {
    "load from text (facts/s)": 50_000,
    "load from terms (facts/s)": 500_000,
    "(a) code(o500, 500)": 1_000_000,
    "(b) color(o500, ?C)": 1_000_000,
    "(c) object(?X, class_3), code(?X, 777)": 200_000,
    "(d) all: object(?X, class_3), visible(?X), color(?X, red)": 500,
    "(e) all: code(?X, ?C), ?C > N-5": 10_000,
    "(f) replace position(o1, ...) (updates/s)": 300_000,
}


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--sizes", type=int, nargs="+", default=[1_000, 10_000, 100_000])
    sizes = parser.parse_args().sizes
    table = {n: measure(n) for n in sizes}
    width = max(len(label) for label in TARGETS)
    header = f"{'per second':<{width}}" + "".join(f"{f'N={n:,}':>14}" for n in sizes)
    judged = TARGET_SIZE in table
    print(header + f"{'target@100k':>14}" + ("  verdict at N=100,000" if judged else ""))
    print("-" * len(header + " " * 14))
    missed = 0
    for label, target in TARGETS.items():
        row = f"{label:<{width}}" + "".join(f"{table[n][label]:>14,.0f}" for n in sizes) + f"{target:>14,}"
        if judged:
            met = table[TARGET_SIZE][label] >= target
            missed += not met
            row += f"  {'met' if met else f'MISSED ({table[TARGET_SIZE][label] / target:.2f}x the target)'}"
        print(row)
    if judged:
        print(f"verdict: {len(TARGETS) - missed} of {len(TARGETS)} targets met at N=100,000")
    else:
        print("verdict: none; the targets are for N=100,000 (--sizes 100000 judges them)")

if __name__ == "__main__":
    main()
