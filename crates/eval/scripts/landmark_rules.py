#!/usr/bin/env python3
"""Replays rules for choosing among the verified hypotheses with landmarks, on the lines of
the `hypotheses` example run with `--landmarks N` (docs/placement.md, "Landmarks"): per
pair, the hypothesis the placement rule picks, then the landmark rule: the definite
hypotheses whose landmark error is within `tolerance` of the smallest (among those costing
at most `cap` times the cheapest definite one) remain, and the cheapest of them is chosen
unless the placement pick remains. Prints the per-hypothesis map errors of the picks
(`error`, before the landmarks are pinned) for each rule.

    python3 crates/eval/scripts/landmark_rules.py LANDMARKS.jsonl ...
"""
import sys

from placement_rules import decide, pairs, summary

# The library's rule: LANDMARK_TOLERANCE, LANDMARK_COST_CAP (src/maps/hypotheses.rs).
RULE = (0.1, None)


def landmark_pick(hs, start, rule):
    tolerance, cap = rule
    definite = [i for i, h in enumerate(hs) if h["hypothesis"] != "symmetric"]
    if cap is not None:
        cheapest = min(hs[i]["cost"] for i in definite)
        definite = [i for i in definite if hs[i]["cost"] <= cap * cheapest]
    errs = {i: hs[i]["landmark_error"] for i in definite if hs[i]["landmark_error"] is not None}
    if not errs:
        return start
    best = min(errs.values())
    kept = [i for i in errs if errs[i] <= best + tolerance]
    if start in kept:
        return start
    return min(kept, key=lambda i: (hs[i]["cost"], i))


def main():
    data = pairs(sys.argv[1:])
    rules = [RULE, (0.05, None), (0.05, 3.0), (0.1, 3.0), (0.05, 2.0), (0.1, 2.0), (0.2, 3.0), (0.05, 5.0)]
    rows = {r: [] for r in rules}
    for key, hs in sorted(data.items()):
        if any("error" not in h for h in hs):
            continue
        start, _ = decide(hs, "auto")
        for rule in rules:
            rows[rule].append((hs[landmark_pick(hs, start, rule)]["error"], key))
    for rule in rules:
        errs = [e for e, _ in rows[rule]]
        print(f"tolerance {rule[0]} cost cap {rule[1]}:", summary(errs))
        for e, key in sorted(rows[rule], reverse=True)[:3]:
            print(f"    {key[0]} {key[1]} -> {key[2]}: {e:.3f}")


if __name__ == "__main__":
    main()
