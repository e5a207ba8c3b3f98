#!/usr/bin/env python3
"""The render diagnostics judged both ways (issue 48): every bundled render scene at its default
study, for each seed given, through the native CLI; prints a markdown table of each estimator's
contribution bound (docs/render-scenes.md, "Bounded contributions"), its heavy_tail severity
and the tail index of its deepest level.

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
          ") | tail index |")
    print("|---|---|---|---|---|")
    for scene in scenes:
        rows = {}
        for seed in seeds:
            out = subprocess.run([args.mcplay, "run", str(scene), "--format", "json", "--seed",
                                  str(seed), "--quiet"], check=True, capture_output=True, text=True)
            for e in json.loads(out.stdout)["estimators"]:
                sev = next((w["severity"] for w in e["warnings"] if w["code"] == "heavy_tail"), "-")
                tail = e["levels"][-1].get("tail_index") if e["levels"] else None
                row = rows.setdefault(e["name"], [e["contribution_bound"]["bounded"], [], []])
                row[1].append(sev)
                row[2].append("-" if tail is None else f"{tail:.2f}")
        for name, (bounded, sevs, tails) in rows.items():
            print(f"| {scene.stem} | {name} | {'yes' if bounded else 'no'} | {', '.join(sevs)} | "
                  f"{', '.join(tails)} |")


if __name__ == "__main__":
    main()
