#!/usr/bin/env python3
"""The goals table of docs/remesh.md: `remora remesh --json` on the meshes of ../shared/data, raw
and smoothed (--low-pass 2, the editor's base surface), one Markdown row each.

Usage: bench/remesh_goals.py [--remora build/bin/remora] [--data ../shared/data] [--jobs 2]
                             [--only NAME ...] [extra remesh options after --]
A ✗ marks a missed goal; "flat" counts zero-area output faces (must stay 0).
"""
import argparse
import concurrent.futures
import json
import os
import subprocess
import sys
import tempfile

MESHES = [
    ("fandisk", "cad/fandisk.obj"),
    ("fertility", "genus/fertility.off"),
    ("lucy", "scans/lucy.ply"),
    ("armadillo", "scans/armadillo.obj"),
    ("camelhead (open)", "open/camelhead.off"),
    ("AcrossRiver (open)", "heightfield/AcrossRiver.stl"),
    ("bunny (5 holes)", "scans/bunny.ply"),
    ("conrod (CAD)", "cad/conrod.stl"),
    ("gears (CAD, 7 bodies)", "cad/gears.stl"),
    ("featuretype (CAD, seams welded)", "cad/featuretype.STL"),
    ("blade (CAD needles)", "cad/blade.off"),
]


def run(remora, path, low_pass, extra):
    with tempfile.TemporaryDirectory() as tmp:
        cmd = [remora, "remesh", path, "-o", os.path.join(tmp, "out.ply"), "--json"] + extra
        if low_pass:
            cmd += ["--low-pass", "2"]
        out = subprocess.run(cmd, capture_output=True, text=True, check=True).stdout
        return json.loads(out)


def row(name, d):
    eq, cyc = d["after_equalization"], d["after_cycles"]
    mad = eq["vertex_area_mixed"]["rel_mad"]
    var = (cyc["vertex_area_mixed"]["rel_std"] / eq["vertex_area_mixed"]["rel_std"]) ** 2
    defect = d["symmetry_defect"]["output"]
    inside = d["symmetry_defect"].get("output_interior_rows", defect)
    min_deg = eq["angles"]["min_deg"]
    mean_dev = eq["angles"]["mean_abs_deviation_from_60_deg"]
    excess = d["correspondence"]["tracked_excess_mean"]
    flat = eq["zero_area_faces"]
    band = d["edges_in_band_percent"]["output"]

    def mark(ok):
        return "" if ok else " ✗"

    defect_cell = f"{defect:.3f}{mark(defect <= 0.06)}"
    if defect > 0.06 and eq["boundary_vertices"] > 0:
        defect_cell += f" (inside: {inside:.3f})"
    return (f"| {name} | {mad:.3f}{mark(mad <= 0.05)} | {var:.1f}×{mark(var >= 5)} | {defect_cell} "
            f"| {min_deg:.1f}{mark(min_deg >= 25)} | {mean_dev:.2f}{mark(mean_dev <= 7)} "
            f"| {band:.1f}{mark(band >= 99)} | {excess:.0e} | {flat}{mark(flat == 0)} |")


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--remora", default="build/bin/remora")
    ap.add_argument("--data", default="../shared/data")
    ap.add_argument("--jobs", type=int, default=2)
    ap.add_argument("--only", nargs="*", default=None, help="mesh names (prefixes) to run")
    ap.add_argument("extra", nargs="*", help="extra `remora remesh` options (after --)")
    args = ap.parse_args()
    jobs = []
    for name, rel in MESHES:
        if args.only and not any(name.startswith(o) for o in args.only):
            continue
        path = os.path.join(args.data, rel)
        if not os.path.exists(path):
            print(f"skipped {name}: {path} not found", file=sys.stderr)
            continue
        short = name.split(" (")[0]
        jobs += [(name, path, False), (f"{short}, σ = 2", path, True)]
    with concurrent.futures.ThreadPoolExecutor(max_workers=args.jobs) as pool:
        futures = [pool.submit(run, args.remora, p, lp, args.extra) for _, p, lp in jobs]
        print("| mesh | rel MAD ≤ 0.05 | var ↓ ≥ 5× | symmetry defect ≤ 0.06 | min angle ≥ 25° "
              "| mean \\|θ−60°\\| ≤ 7° | edges in [4/5, 4/3] l ≥ 99 % "
              "| tracked input → output, mean excess / l | flat faces |")
        print("|---|---|---|---|---|---|---|---|---|")
        for (name, _, _), fut in zip(jobs, futures):
            try:
                print(row(name, fut.result()), flush=True)
            except subprocess.CalledProcessError as e:
                print(f"| {name} | failed: {e.stderr.strip()[:80]} |", flush=True)


if __name__ == "__main__":
    main()
