#!/usr/bin/python3
"""Cost model of one distributed fix coul/fmm evaluation (doc/scaling.md), fitted to the counts
of bench_distributed and projected to large N and P.

Usage: scaling_model.py COUNTS [--N 1e8] [--P 1024] [--latency 2e-6] [--bandwidth 2e8]
  COUNTS: a file holding bench_distributed's table (its stdout, or doc/fmm-distributed.md)

Fitted (deposition geometry, accuracy 1e-4, x-y grid of ranks):
  t_eval(n)  = a n^b      one rank's evaluation of n charges (the P = 1 rows; this machine's core)
  B(n)       = c n^e      bytes the busiest rank receives at n = N / P charges per rank (the weak
                          rows at P = 8, where every rank has neighbours on all sides)
  M(n)       = m n^g      the busiest rank's solver memory (same rows)
Projected: t = t_eval(n) (1 + f_remote) + (P - 1) (latency + t_walk) + B(n) / bandwidth
           + 4 log2(P) latency (the allreduces and the boxes' allgather),
with f_remote = (received particles) / n the remote share of the near-field work (the received
particles fitted as k n^h on the same rows)
and t_walk the LET walk for one far rank (an assumption, not measured: see doc/scaling.md).
"""
import argparse
import math
import re
import sys

import numpy as np


def read_rows(path):
    rows = []
    for line in open(path):
        cells = [c.strip() for c in line.strip().strip("|").split("|")]
        if len(cells) < 11 or cells[0] not in ("deposition", "cube"):
            continue
        rows.append(dict(geometry=cells[0], scaling=cells[1], N=float(cells[2]), P=int(cells[3]),
                         grid=cells[4], bytes=float(cells[5]), memory=float(cells[7]) * 1e6,
                         let_particles=float(cells[10]),
                         t=float(cells[11]) if len(cells) > 11 and cells[11] else math.nan))
    return rows


def power_fit(x, y):
    b, loga = np.polyfit(np.log(x), np.log(y), 1)
    return math.exp(loga), b


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("counts")
    ap.add_argument("--N", type=float, default=1e8)
    ap.add_argument("--P", type=int, default=1024)
    ap.add_argument("--latency", type=float, default=2e-6, help="seconds per message")
    ap.add_argument("--bandwidth", type=float, default=2e8,
                    help="bytes/s one rank receives while all ranks exchange (a 100 Gb/s link shared "
                         "by 64 ranks of a node)")
    ap.add_argument("--walk", type=float, default=5e-6, help="seconds of LET walk per far rank")
    args = ap.parse_args()

    rows = [r for r in read_rows(args.counts) if r["geometry"] == "deposition"]
    if not rows:
        sys.exit(f"no deposition rows of bench_distributed in {args.counts}")
    one = [r for r in rows if r["P"] == 1 and not math.isnan(r["t"])]
    weak8 = [r for r in rows if r["scaling"] == "weak" and r["P"] == 8 and not r["grid"].endswith("x2")]
    a, b = power_fit([r["N"] for r in one], [r["t"] for r in one])
    c, e = power_fit([r["N"] / r["P"] for r in weak8], [r["bytes"] for r in weak8])
    m, g = power_fit([r["N"] / r["P"] for r in weak8], [r["memory"] for r in weak8])
    k, h = power_fit([r["N"] / r["P"] for r in weak8], [r["let_particles"] for r in weak8])
    m1, g1 = power_fit([r["N"] for r in one], [r["memory"] for r in one])
    print(f"fits: t_eval = {a:.3g} n^{b:.3f} s;  B = {c:.3g} n^{e:.3f} bytes;  M = {m:.3g} n^{g:.3f} "
          f"bytes;  received particles = {k:.3g} n^{h:.3f};  one rank's memory = {m1:.3g} N^{g1:.3f}")
    print(f"  from P = 1 rows n = {[int(r['N']) for r in one]}, weak P = 8 rows n = "
          f"{[int(r['N'] / r['P']) for r in weak8]}")

    n = args.N / args.P
    f_remote = k * n**h / n
    t_comp = a * n**b * (1.0 + f_remote)
    t_lat = (args.P - 1) * (args.latency + args.walk) + 4 * math.log2(args.P) * args.latency
    bytes_ = c * n**e
    t_bw = bytes_ / args.bandwidth
    total = t_comp + t_lat + t_bw
    print(f"\nprojection: N = {args.N:.3g} charges on P = {args.P} ranks (n = {n:.4g} per rank), "
          f"latency {args.latency:.3g} s, bandwidth {args.bandwidth:.3g} B/s per rank, walk "
          f"{args.walk:.3g} s per far rank")
    print(f"  compute (own + received near field, {f_remote:.2f} of own) {t_comp:.3g} s")
    print(f"  messages and walks (P - 1 partners)  {t_lat:.3g} s")
    print(f"  received bytes {bytes_:.3g} -> {t_bw:.3g} s")
    print(f"  memory per rank {m * n**g:.3g} bytes")
    print(f"  one evaluation ~ {total:.3g} s; parallel efficiency vs one rank's rate "
          f"{a * n**b / total:.2f}")
    rep_bytes = 40.0 * args.N
    print(f"  the replicated solver instead: {rep_bytes:.3g} bytes received per rank "
          f"({rep_bytes / args.bandwidth:.3g} s) and the whole tree on every rank "
          f"({m1 * args.N**g1:.3g} bytes by the one-rank memory fit)")


if __name__ == "__main__":
    main()
