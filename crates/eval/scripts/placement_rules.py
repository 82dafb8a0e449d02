#!/usr/bin/env python3
"""Replays rules for using the shapes' placement on the lines of the `hypotheses` example
(docs/placement.md): per pair, the choice by cost (placement = ignore, with the close call
settled by full-resolution consistency as the library does), the choice a placement rule
makes, their map errors, and how often the rule changes the intrinsic choice when B is
turned at random (each hypothesis's implied rotation R becomes R Q^T for a random Q; the
placement hypothesis is left out there, its map comes from the frame).

    python3 crates/eval/scripts/placement_rules.py ORACLE.jsonl ... [--rotations N] [--report]

`--report` prints, per dataset, the map errors of the default rule and of `ignore`, and the
confidence curve of both (the confidence replayed as `hypotheses::confidence` computes it:
competitors the frame rules out are not counted; a close call caps it as `Verdict::settle`
does; distances between maps are the full-resolution ones, the library uses samples').
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


COST_SCALE, MARGIN_SCALE, FULL_MARGIN_SCALE = 0.5, 0.05, 0.05
# The library's rule: NEAR_TURN, FAR_TURN, PLACEMENT_COST_RATIO (src/maps/placement.rs).
RULE = (30, 100, 1.35)


def confidence(hs, pick, ruled):
    best = hs[pick]["cost"]
    consistency = math.exp(-best / COST_SCALE)
    rivals = [h["cost"] for i, h in enumerate(hs) if h["dist"][pick] > DIFFERENT_MAP and not ruled[i]]
    if not rivals:
        return consistency
    runner = min(rivals)
    rel = (runner - best) / max(runner, 1e-12)
    return consistency * (1 - math.exp(-max(rel, 0) / MARGIN_SCALE))


def decide(hs, placement):
    """The library's choice and confidence for `placement` ("auto" or "ignore")."""
    with_own = placement != "ignore"
    idx = [i for i, h in enumerate(hs) if with_own or h["hypothesis"] != "placement"]
    sub = [hs[i] for i in idx]
    turns = [h["turn"] for h in sub]
    p = frame_pick(sub, turns, RULE) if with_own else None
    if p is not None:
        ruled = [h["dist"][p] > DIFFERENT_MAP and turns[i] > RULE[0] for i, h in enumerate(sub)]
        return idx[p], confidence(sub, p, ruled)
    # By cost, as by_cost, with the close call's cap on the confidence.
    cost = lambda i: sub[i]["cost"]
    chosen = min(range(len(sub)), key=lambda i: (cost(i), i))
    definite = [i for i in range(len(sub)) if sub[i]["hypothesis"] != "symmetric"]
    if sub[chosen]["hypothesis"] == "symmetric":
        same = [i for i in definite if sub[i]["dist"][chosen] <= DIFFERENT_MAP]
        within = [i for i in definite if cost(i) < SYMMETRIC_YIELDS * cost(chosen)]
        if same or within:
            chosen = min(same or within, key=lambda i: (cost(i), i))
    none = [False] * len(sub)
    conf = confidence(sub, chosen, none)
    rivals = [i for i in definite if i != chosen and sub[i]["dist"][chosen] > DIFFERENT_MAP]
    if rivals:
        r = min(rivals, key=lambda i: (cost(i), i))
        if cost(r) < CLOSE_CALL * cost(chosen):
            full = lambda i: sub[i]["orient_full"] * sub[i]["cover_full"]
            if full(r) > full(chosen):
                rel = (full(r) - full(chosen)) / max(full(r), 1e-12)
                c2 = math.exp(-cost(r) / COST_SCALE) * (1 - math.exp(-rel / FULL_MARGIN_SCALE))
                return idx[r], min(max(c2, 0.0), conf)
    return idx[chosen], conf


def report(data):
    by_set = defaultdict(lambda: {"auto": [], "ignore": []})
    for key, hs in sorted(data.items()):
        if any("error" not in h for h in hs):
            continue
        for mode in ("auto", "ignore"):
            pick, conf = decide(hs, mode)
            by_set[key[0]][mode].append((hs[pick]["error"], f"{key[1]} -> {key[2]}", conf))
    print("| dataset | placement | pairs | mean | median | worst pair | above 0.05 |")
    print("|---|---|---|---|---|---|---|")
    for name, modes in sorted(by_set.items()):
        for mode in ("auto", "ignore"):
            rows = sorted(modes[mode])
            n = len(rows)
            worst = rows[-1]
            print(f"| {name} | {mode} | {n} | {sum(r[0] for r in rows)/n:.4f} | {rows[n//2][0]:.4f} | "
                  f"{worst[0]:.4f} ({worst[1]}) | {sum(r[0] > 0.05 for r in rows)} |")
    print()
    print("| threshold | failed flagged (auto) | good flagged (auto) | failed flagged (ignore) | good flagged (ignore) |")
    print("|---|---|---|---|---|")
    everything = {m: [r for modes in by_set.values() for r in modes[m]] for m in ("auto", "ignore")}
    for t in (0.1, 0.2, 0.3, 0.4, 0.45, 0.5, 0.6, 0.7):
        cells = []
        for m in ("auto", "ignore"):
            bad = [c for e, _, c in everything[m] if e > 0.05]
            good = [c for e, _, c in everything[m] if e <= 0.05]
            cells.append(f"{sum(c < t for c in bad)}/{len(bad)}")
            cells.append(f"{sum(c < t for c in good)}/{len(good)} ({100*sum(c < t for c in good)/max(len(good),1):.0f}%)")
        print(f"| {t} | {cells[0]} | {cells[1]} | {cells[2]} | {cells[3]} |")
    print()
    for m in ("auto",):
        for e, name, c in sorted(everything[m], reverse=True):
            if e > 0.05:
                print(f"failed ({m}): {name} {e:.3f} confidence {c:.2f}")


def main():
    args = sys.argv[1:]
    if "--report" in args:
        args.remove("--report")
        report(pairs(args))
        return
    n_rot = 0
    if "--rotations" in args:
        i = args.index("--rotations")
        n_rot = int(args[i + 1])
        del args[i : i + 2]
    data = pairs(args)
    rules = [RULE, (30, 100, 3.0), (30, 100, 1.5), (30, 150, 1.5), (30, 100, 1.2), (30, 120, 1.35), (45, 90, 1.35), (20, 100, 1.35)]
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
