#!/usr/bin/env python3
"""The tunnelling probe's verdicts: reads the dumps of peers/scenes/bullets.ron after 30 steps
(ballpit's `run --dump`, peers' `--dump DIR`) and says, for each probe, whether it bounced or
tunnelled, with the effective restitution of the pairs (relative speed after over before).

usage: tunnel.py NAME=DUMP.json [NAME=DUMP.json ...]
"""
import json
import sys

PAIRS = [("head-on 500 px/s", 0, 1, 1000.0), ("head-on 2,000 px/s", 2, 3, 4000.0),
         ("head-on 6,000 px/s", 4, 5, 12000.0), ("6,000 px/s into a ball at rest", 6, 7, 6000.0)]
WALL, HALF = 8, 5000.0


def verdicts(balls):
    rows = []
    for name, a, b, closing in PAIRS:
        if balls[a]["x"] > balls[b]["x"]:
            rows.append((name, "tunnelled", "-"))
        else:
            e = (balls[b]["vx"] - balls[a]["vx"]) / closing
            rows.append((name, "bounced", f"{e:.3f}"))
    wall = balls[WALL]
    if wall["x"] > HALF:
        rows.append(("6,000 px/s at a wall", "tunnelled (out of the arena)", "-"))
    else:
        rows.append(("6,000 px/s at a wall", "bounced", f"{-wall['vx'] / 6000.0:.3f}"))
    return rows


def main():
    if len(sys.argv) < 2:
        sys.exit(__doc__)
    results = {}
    for argument in sys.argv[1:]:
        name, path = argument.split("=", 1)
        balls = sorted(json.load(open(path))["balls"], key=lambda ball: ball["id"])
        results[name] = verdicts(balls)
    names = list(results)
    print("| probe | " + " | ".join(names) + " |")
    print("|---|" + "---|" * len(names))
    for row in range(len(PAIRS) + 1):
        cells = []
        for name in names:
            probe, verdict, e = results[name][row]
            cells.append(verdict if e == "-" else f"{verdict}, e {e}")
        print(f"| {results[names[0]][row][0]} | " + " | ".join(cells) + " |")


main()
