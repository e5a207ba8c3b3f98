#!/usr/bin/env python3
"""The render diagnostics judged both ways (issue 48): every bundled render scene at its default
study, for each seed given, through the native CLI; prints a markdown table of each estimator's
contribution bound (docs/render-scenes.md, "Bounded contributions": yes, no, or infinite
variance by construction), the severities of its heavy_tail and rare_large_errors flags, any
other warning or error it gets, and the tail index of its deepest level.

    python3 bench/render_flags_table.py [--mcplay build/mcplay] [--seeds 1,2]
"""
import argparse
import json
import pathlib
import subprocess

ROOT = pathlib.Path(__file__).resolve().parent.parent


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--mcplay", default=str(ROOT / "build" / "mcplay"))
    ap.add_argument("--seeds", default="1,2")
    args = ap.parse_args()
    seeds = [int(s) for s in args.seeds.split(",")]
    scenes = sorted(p for p in (ROOT / "scenes").glob("*.json")
                    if "render" in json.loads(p.read_text()))
    print("| scene | estimator | bounded | heavy_tail (seed " + ", ".join(map(str, seeds)) +
          ") | rare_large_errors | other warnings | tail index |")
    print("|---|---|---|---|---|---|---|")
    for scene in scenes:
        rows = {}
        for seed in seeds:
            out = subprocess.run([args.mcplay, "run", str(scene), "--format", "json", "--seed",
                                  str(seed), "--quiet"], check=True, capture_output=True, text=True)
            for e in json.loads(out.stdout)["estimators"]:
                def severity(code):
                    return next((w["severity"] for w in e["warnings"] if w["code"] == code), "-")
                others = {w["code"] for w in e["warnings"]
                          if w["severity"] in ("warning", "error")
                          and w["code"] not in ("heavy_tail", "rare_large_errors")}
                tail = e["levels"][-1].get("tail_index") if e["levels"] else None
                b = e["contribution_bound"]
                bound = ("infinite" if b.get("infinite_variance") else
                         "yes" if b["bounded"] else "no")
                row = rows.setdefault(e["name"], [bound, [], [], set(), []])
                row[1].append(severity("heavy_tail"))
                row[2].append(severity("rare_large_errors"))
                row[3] |= others
                row[4].append("-" if tail is None else f"{tail:.2f}")
        for name, (bound, heavy, rare, others, tails) in rows.items():
            print(f"| {scene.stem} | {name} | {bound} | {', '.join(heavy)} | {', '.join(rare)} | "
                  f"{', '.join(sorted(others)) or '-'} | {', '.join(tails)} |")


if __name__ == "__main__":
    main()
