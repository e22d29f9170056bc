#!/usr/bin/python3
"""Order of charging: a binary powder charged by its contacts during the deposition against the
same powder with its final charges given at injection.  Reads the runs made by run.sh
(<variant>-<seed>/log.lammps and final.dump), prints the table of phi, <Z> and the charges per
species (mean and standard deviation over the seeds), writes charges.csv (each species' mean
charge against depth below the bed top) and order.png."""
import glob
import os
import re
import sys

import numpy as np
import pandas as pd
import matplotlib
matplotlib.use("Agg")
import matplotlib.pyplot as plt

E0 = 1.602176634e-19
RP = 2e-6
SLAB_RP = 4.0   # depth bins of the charge profile, in r_p


def read_dump(path):
    with open(path) as f:
        lines = f.readlines()
    at = next(k for k, l in enumerate(lines) if l.startswith("ITEM: ATOMS"))
    cols = lines[at].split()[2:]
    data = np.array([[float(x) for x in l.split()] for l in lines[at + 1:]])
    return pd.DataFrame(data, columns=cols)


def read_result(path):
    with open(path) as f:
        text = f.read()
    m = re.findall(r"GC RESULT .* phi (\S+) Z (\S+)", text)
    return float(m[-1][0]), float(m[-1][1])


def run(folder):
    phi, z = read_result(os.path.join(folder, "log.lammps"))
    atoms = read_dump(os.path.join(folder, "final.dump"))
    atoms["q_e"] = atoms["q"] / E0
    # depth below the bed top: the top is the mean height of the highest 10% of the particles
    top = atoms["z"].quantile(0.9)
    atoms["depth_rp"] = (top - atoms["z"]) / RP
    return phi, z, atoms


def cpu_seconds(folder):
    for name in ("cpu.txt", "time.txt"):
        path = os.path.join(folder, name)
        if os.path.isfile(path):
            with open(path) as f:
                return float(f.read().split()[0])
    return float("nan")


def final_charges(where):
    """the pooled final charges of the contact-charged runs: mean and sd per species, in e"""
    qs = {1: [], 2: []}
    for folder in sorted(glob.glob(os.path.join(where, "tribo-[0-9]*"))):
        atoms = read_dump(os.path.join(folder, "final.dump"))
        for s in (1, 2):
            qs[s] += list(atoms.loc[atoms["type"] == s, "q"] / E0)
    print(" ".join(f"{np.mean(qs[s]):.0f} {np.std(qs[s], ddof=1):.0f}" for s in (1, 2)))


def main(where):
    rows, profiles = [], []
    for folder in sorted(glob.glob(os.path.join(where, "*-[0-9]*"))):
        if not os.path.isfile(os.path.join(folder, "final.dump")):
            continue
        variant, seed = os.path.basename(folder).rsplit("-", 1)
        phi, z, atoms = run(folder)
        row = {"variant": variant, "seed": int(seed), "phi": phi, "Z": z,
               "cpu_s": cpu_seconds(folder)}
        for s in (1, 2):
            q = atoms.loc[atoms["type"] == s, "q_e"]
            row[f"q{s}_mean"] = q.mean()
            row[f"q{s}_sd"] = q.std()
            row[f"q{s}_neg"] = (q < 0).mean()
        rows.append(row)
        atoms["bin"] = (atoms["depth_rp"] // SLAB_RP) * SLAB_RP + SLAB_RP / 2
        prof = atoms.groupby(["bin", "type"])["q_e"].mean().reset_index()
        prof["variant"], prof["seed"] = variant, int(seed)
        profiles.append(prof)
    runs = pd.DataFrame(rows)
    stats = runs.drop(columns="seed").groupby("variant").agg(["mean", "std"])
    pd.set_option("display.width", 200)
    print(runs.to_string(index=False))
    print(stats.to_string())
    prof = pd.concat(profiles)
    prof.to_csv(os.path.join(where, "charges.csv"), index=False)
    runs.to_csv(os.path.join(where, "runs.csv"), index=False)

    fig, ax = plt.subplots(1, 2, figsize=(9, 3.6))
    for variant, style in (("tribo", "-"), ("assigned", "--")):
        for s, colour in ((1, "tab:red"), (2, "tab:blue")):
            p = prof[(prof["variant"] == variant) & (prof["type"] == s)]
            if p.empty:
                continue
            g = p.groupby("bin")["q_e"].agg(["mean", "std"]).reset_index()
            g = g[g["bin"] < 40]
            ax[0].errorbar(g["bin"], g["mean"] / 1e3, yerr=g["std"] / 1e3, ls=style, color=colour,
                           marker="o", ms=3, capsize=2,
                           label=f"species {s}, {'contacts' if variant == 'tribo' else 'given'}")
    ax[0].axhline(0, color="k", lw=0.5)
    ax[0].set_xlabel("depth below the bed top [r_p]")
    ax[0].set_ylabel("mean charge [10^3 e]")
    ax[0].legend(fontsize=7)
    for k, (variant, label) in enumerate((("tribo", "charged by contacts"),
                                          ("assigned", "charges given at injection"))):
        r = runs[runs["variant"] == variant]
        if r.empty:
            continue
        ax[1].errorbar([k], [r["phi"].mean()], yerr=[r["phi"].std()], fmt="o", color="k")
        ax[1].errorbar([k + 0.15], [r["Z"].mean() / 10], yerr=[r["Z"].std() / 10], fmt="s",
                       color="tab:green")
    ax[1].set_xticks([0.07, 1.07])
    ax[1].set_xticklabels(["contacts", "given"])
    ax[1].set_xlim(-0.5, 1.6)
    ax[1].set_ylabel("phi (circles), <Z>/10 (squares)")
    fig.tight_layout()
    fig.savefig(os.path.join(where, "order.png"), dpi=120)


if __name__ == "__main__":
    if len(sys.argv) > 1 and sys.argv[1] == "--final-charges":
        final_charges(sys.argv[2] if len(sys.argv) > 2 else ".")
    else:
        main(sys.argv[1] if len(sys.argv) > 1 else ".")
