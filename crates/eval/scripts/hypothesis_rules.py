#!/usr/bin/env python3
"""Replays selection rules on the `hypotheses` example's JSON lines
(docs/decisions.md, "Confidence").

    cargo run --release -p shapecorr-eval --example hypotheses -- --cache DIR --limit N \
        DATASET > DATASET.jsonl
    python3 crates/eval/scripts/hypothesis_rules.py *.jsonl

Every hypothesis's map is independent of the rule that picks among them, so one run of the
example scores every rule: per dataset the mean / worst / pairs above 0.05 of the picked
maps (no flip), then the confidence's flags (failed / good pairs below the threshold) over a
grid of scales. `dist` (full-resolution mean image distance) stands in for the sample-map
distance the library uses. The tables in docs/decisions.md ("Symmetric hypothesis",
"Confidence") were made by this script.
"""
import collections
import json
import math
import statistics
import sys

CLOSE_CALL = 1.5
DIFFERENT_MAP = 0.05
FAILED = 0.05


def load(files):
    pairs = collections.OrderedDict()
    for f in files:
        for line in open(f):
            r = json.loads(line)
            pairs.setdefault((r["dataset"], r["source"], r["target"]), []).append(r)
    return pairs


def without_rearranged(hs):
    keep = [i for i, h in enumerate(hs) if not h["hypothesis"].startswith("rearranged")]
    return [dict(hs[i], dist=[hs[i]["dist"][j] for j in keep]) for i in keep]


def pick(hs, symmetric_yields=None, symmetric=True):
    """The library's rule: lowest cost; the symmetric hypothesis gives way (ratio
    `symmetric_yields`, None: never); then the close call by full-resolution consistency."""
    cost = [h["cost"] for h in hs]
    kind = [h["hypothesis"] for h in hs]
    dist = [h["dist"] for h in hs]
    full = [h["orient_full"] * h["cover_full"] for h in hs]
    candidates = [i for i in range(len(hs)) if symmetric or kind[i] != "symmetric"]
    lowest = lambda among: min(among, key=lambda i: (cost[i], i)) if among else None
    chosen = lowest(candidates)
    if symmetric_yields is not None and kind[chosen] == "symmetric":
        definite = [i for i in candidates if kind[i] != "symmetric"]
        same = [i for i in definite if dist[i][chosen] <= DIFFERENT_MAP]
        best = lowest(definite)
        if same:
            chosen = lowest(same)
        elif best is not None and cost[best] < symmetric_yields * cost[chosen]:
            chosen = best
    rivals = [i for i in candidates if dist[i][chosen] > DIFFERENT_MAP and kind[i] != "symmetric"]
    rival = lowest(rivals)
    if rival is not None and cost[rival] < CLOSE_CALL * cost[chosen] and full[rival] > full[chosen]:
        chosen = rival
    return chosen


def confidence(hs, chosen, cost_scale, margin_scale):
    best = hs[chosen]["cost"]
    rivals = [h["cost"] for i, h in enumerate(hs) if hs[chosen]["dist"][i] > DIFFERENT_MAP]
    margin = 1.0
    if rivals:
        runner_up = min(rivals)
        margin = 1 - math.exp(-max(0.0, (runner_up - best) / runner_up) / margin_scale)
    return math.exp(-best / cost_scale) * margin


def table(pairs, name, transform=lambda hs: hs, **rule):
    by = collections.defaultdict(list)
    for key, hs in pairs.items():
        hs = transform(hs)
        by[key[0]].append(hs[pick(hs, **rule)]["error"])
    cells = [f"{statistics.mean(v):.4f} / {max(v):.3f} / {sum(e > FAILED for e in v)}" for d, v in by.items()]
    print(f"| {name} | " + " | ".join(cells) + " |")


def main(files):
    pairs = load(files)
    print("| rule | " + " | ".join(sorted({k[0] for k in pairs}, key=list(k[0] for k in pairs).index)) + " |")
    table(pairs, "lowest cost, no rearrangement (before)", without_rearranged)
    table(pairs, "no symmetric hypothesis", symmetric=False)
    for ratio in (1.0, 1.25, 1.5, 2.0, 3.0):
        table(pairs, f"symmetric gives way, ratio {ratio}", symmetric_yields=ratio)
    table(pairs, "symmetric gives way 1.5, no rearrangement", without_rearranged, symmetric_yields=1.5)
    by = collections.defaultdict(list)
    for key, hs in pairs.items():
        by[key[0]].append(min(h["error"] for h in hs))
    print("| best hypothesis (oracle) | " + " | ".join(f"{statistics.mean(v):.4f} / {max(v):.3f} / {sum(e > FAILED for e in v)}" for v in by.values()) + " |")
    print("\nconfidence below 0.45 (symmetric gives way, 1.5): failed / good pairs flagged")
    for cost_scale in (0.5, 0.75, 1.0, 1.5):
        row = []
        for margin_scale in (0.03, 0.05, 0.07, 0.2):
            flags = []
            for hs in pairs.values():
                c = pick(hs, symmetric_yields=1.5)
                flags.append((hs[c]["error"] > FAILED, confidence(hs, c, cost_scale, margin_scale) < 0.45))
            n_failed = sum(f for f, _ in flags)
            row.append(f"{sum(f and x for f, x in flags)}/{n_failed}, {sum((not f) and x for f, x in flags)}/{len(flags) - n_failed}")
        print(f"cost scale {cost_scale}: margin scale 0.03 / 0.05 / 0.07 / 0.2: " + " | ".join(row))


if __name__ == "__main__":
    main(sys.argv[1:])
