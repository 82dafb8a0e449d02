#!/usr/bin/env python3
"""Replays rules for using the shapes' placement on the lines of the `hypotheses` example
(docs/placement.md): per pair, the choice by cost (placement = ignore, with the close call
settled by full-resolution consistency as the library does), the choice a placement rule
makes, their map errors, and how often the rule changes the intrinsic choice when B is
turned at random (each hypothesis's implied rotation R becomes R Q^T for a random Q; the
placement hypothesis is left out there, its map comes from the frame).

    python3 crates/eval/scripts/placement_rules.py ORACLE.jsonl ... [--rotations N]
"""
import json
import math
import random
import sys
from collections import defaultdict

DIFFERENT_MAP, CLOSE_CALL, SYMMETRIC_YIELDS = 0.05, 1.5, 1.5


def pairs(paths):
    out = defaultdict(list)
    for path in paths:
        for line in open(path):
            r = json.loads(line)
            out[(r["dataset"], r["source"], r["target"])].append(r)
    return out


def by_cost(hs, with_placement=False):
    """The library's choice by cost: lowest cost, the symmetric hypothesis giving way, then
    a close call settled at full resolution (the placement hypothesis competes only when
    placement is not ignored)."""
    idx = [i for i, h in enumerate(hs) if with_placement or h["hypothesis"] != "placement"]
    cost = lambda i: hs[i]["cost"]
    chosen = min(idx, key=lambda i: (cost(i), i))
    definite = [i for i in idx if hs[i]["hypothesis"] != "symmetric"]
    if hs[chosen]["hypothesis"] == "symmetric":
        same = [i for i in definite if hs[i]["dist"][chosen] <= DIFFERENT_MAP]
        within = [i for i in definite if cost(i) < SYMMETRIC_YIELDS * cost(chosen)]
        if same:
            chosen = min(same, key=lambda i: (cost(i), i))
        elif within:
            chosen = min(within, key=lambda i: (cost(i), i))
    rivals = [i for i in definite if i != chosen and hs[i]["dist"][chosen] > DIFFERENT_MAP]
    if rivals:
        r = min(rivals, key=lambda i: (cost(i), i))
        if cost(r) < CLOSE_CALL * cost(chosen):
            full = lambda i: hs[i]["orient_full"] * hs[i]["cover_full"]
            if full(r) > full(chosen):
                chosen = r
    return chosen


def angle(r):
    t = (r[0][0] + r[1][1] + r[2][2] - 1) / 2
    return math.degrees(math.acos(max(-1.0, min(1.0, t))))


def matmul_t(r, q):
    """R Q^T."""
    return [[sum(r[i][k] * q[j][k] for k in range(3)) for j in range(3)] for i in range(3)]


def random_rotation(rng):
    q = [rng.gauss(0, 1) for _ in range(4)]
    n = math.sqrt(sum(x * x for x in q))
    w, x, y, z = (c / n for c in q)
    return [
        [1 - 2 * (y * y + z * z), 2 * (x * y - z * w), 2 * (x * z + y * w)],
        [2 * (x * y + z * w), 1 - 2 * (x * x + z * z), 2 * (y * z - x * w)],
        [2 * (x * z - y * w), 2 * (y * z + x * w), 1 - 2 * (x * x + y * y)],
    ]


def frame_pick(hs, turns, rule, with_placement=True):
    """The library's rule (src/maps/placement.rs, `frame_pick`, `Auto`): a region
    hypothesis before the frame's own map; the frame's own map never leaves it undecided."""
    near, far, ratio = rule
    idx = [i for i, h in enumerate(hs) if with_placement or h["hypothesis"] != "placement"]
    own = lambda i: hs[i]["hypothesis"] == "placement"
    cheapest = min(hs[i]["cost"] for i in idx)
    ok = lambda i: hs[i]["hypothesis"] != "symmetric" and hs[i]["cost"] <= ratio * cheapest
    cands = [i for i in idx if ok(i) and turns[i] <= near]
    if not cands:
        return None
    region = [i for i in cands if not own(i)]
    pick = min(region or cands, key=lambda i: (hs[i]["cost"], i))
    for i in idx:
        if not own(i) and hs[i]["dist"][pick] > DIFFERENT_MAP and near < turns[i] < far:
            return None
    return pick


def summary(errors):
    e = sorted(errors)
    n = len(e)
    return f"mean {sum(e)/n:.4f} median {e[n//2]:.4f} worst {e[-1]:.3f} failed {sum(x > 0.05 for x in e)}/{n}"


def main():
    args = sys.argv[1:]
    n_rot = 0
    if "--rotations" in args:
        i = args.index("--rotations")
        n_rot = int(args[i + 1])
        del args[i : i + 2]
    data = pairs(args)
    rules = [(30, 150, 1.5), (30, 100, 3.0), (30, 100, 1.5), (30, 100, 1.3), (20, 120, 1.5), (45, 90, 1.5), (30, 150, 3.0), (20, 160, 1.5)]
    base = []
    per_rule = {r: [] for r in rules}
    changes = {r: [] for r in rules}
    rng = random.Random(7)
    for key, hs in sorted(data.items()):
        if any("error" not in h for h in hs):
            continue
        c = by_cost(hs)
        base.append((hs[c]["error"], key))
        turns = [h["turn"] for h in hs]
        c_auto = by_cost(hs, with_placement=True)
        for rule in rules:
            p = frame_pick(hs, turns, rule)
            pick = c_auto if p is None else p
            per_rule[rule].append((hs[pick]["error"], key, pick != c, hs[c]["error"]))
            changed = 0
            for _ in range(n_rot):
                q = random_rotation(rng)
                t2 = [angle(matmul_t(h["rotation"], q)) for h in hs]
                p2 = frame_pick(hs, t2, rule, with_placement=False)
                if p2 is not None and hs[p2]["dist"][c] > DIFFERENT_MAP:
                    changed += 1
            changes[rule].append(changed)
    print("placement = ignore (by cost):", summary([e for e, _ in base]))
    for rule in rules:
        rows = per_rule[rule]
        print(f"rule near {rule[0]} far {rule[1]} cost ratio {rule[2]}:", summary([r[0] for r in rows]))
        for e, key, switched, e0 in rows:
            if switched:
                print(f"    switched {key[0]} {key[1]} -> {key[2]}: {e0:.3f} -> {e:.3f}")
        if n_rot:
            total = sum(changes[rule])
            print(f"    turned at random: {total} of {n_rot * len(rows)} choices changed")


if __name__ == "__main__":
    main()
