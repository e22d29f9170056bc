"""End to end through the command line: `granular-charged demo --claims` at a tiny size, interrupted
during its second run and started again (resumption), then its JSON results, tables, Table 2
check, figures and rendered packings.

Size: N = 40 particles in L = 6 r_p, injection height H = 60 r_p, gap 1 r_p, Coulomb force every
10 steps; q = 0 and 480 e0, one seed; Table 2 check with q = 0 (control) and 400 e0. Measured
here: ~1.5 s for the neutral run, ~5-9 s for the charged one, ~2 s per Table 2 run, ~25 s for
the whole module on a loaded 2-core machine.

Determinism. The old test compared the seed-averaged phi of charged and neutral packings (a
statistical claim that failed ~1 % of the time by its own account, in 1.5 min). Nothing here is
statistical: single-rank runs with fixed seeds are reproducible, and every assertion is either
an identity (the Python analysis equals the LAMMPS computes; JSON equals what LAMMPS returned)
or physics with a margin argued from closed forms (the Coulomb deceleration of an incident
particle; the Table 2 invariance), far from what a different realisation of the same physics
could produce. The claim "charge lowers phi" is left to `demo`/`reproduce` (reported, not
asserted): at test sizes its effect is within the seed-to-seed scatter.
"""
import json
import math
import os
import re
import signal
import subprocess
import sys
import time
from pathlib import Path

import matplotlib.image as mpimg
import numpy as np
import pandas as pd
import pytest

from granular_charged.analysis import packing
from granular_charged.params import jkr_scales, pair_modulus

N, TRACER = 40, 30
Q = 480.0
SMALL = ["--var", "L_rp", "6", "--var", "H_rp", "60", "--var", "gap_rp", "1"]
ARGS = ["demo", "--claims", "--N", N, "--q", 0, Q, "--seeds", 1, "--table2-q", 0, 400, "--tracer",
        TRACER, *SMALL]


def _env(build_dir):
    from conftest import SRC
    env = dict(os.environ)
    env["PYTHONPATH"] = os.pathsep.join([str(SRC / "python"), str(Path(build_dir) / "python")])
    env["GC_BUILD_DIR"] = str(build_dir)
    return env


@pytest.fixture(scope="module")
def study(cli, build_dir, tmp_path_factory):
    out = tmp_path_factory.mktemp("reproduce")
    runs = out / "runs"
    # 1. start, and interrupt (SIGINT = Ctrl-C) while the second (charged) deposition runs
    # SIGINT as at a terminal, also when the tests run in the background (which ignores it)
    p = subprocess.Popen([sys.executable, "-m", "granular_charged", *map(str, ARGS), "--out", out],
                         cwd=out, env=_env(build_dir), stdout=subprocess.PIPE,
                         stderr=subprocess.PIPE, text=True,
                         preexec_fn=lambda: signal.signal(signal.SIGINT, signal.SIG_DFL))
    t0 = time.monotonic()
    first = second = None
    while time.monotonic() - t0 < 120 and p.poll() is None:
        done = list(runs.glob("*/result.json"))
        if done and first is None:
            first = done[0]
        if first is not None:
            other = [d for d in runs.glob("*") if d != first.parent and (d / "log.lammps").exists()]
            if other:
                second = other[0]
                break
        time.sleep(0.02)
    assert first is not None and second is not None, "the sweep did not reach its second run"
    p.send_signal(signal.SIGINT)
    _, err1 = p.communicate(timeout=60)
    first_mtime = first.stat().st_mtime_ns
    # 2. the same command again: resumes
    r = cli([*ARGS, "--out", out], cwd=out)
    return {"out": out, "interrupted_rc": p.returncode, "interrupted_err": err1, "first": first,
            "first_mtime": first_mtime, "second": second, "second_done_before": None,
            "stdout": r.stdout, "stderr": r.stderr}


def results(study):
    return [json.loads(f.read_text()) | {"dir": f.parent}
            for f in sorted((study["out"] / "runs").glob("*/result.json"))]


def test_interrupted_sweep_resumes(study):
    assert study["interrupted_rc"] == 130, study["interrupted_err"][-2000:]
    assert "interrupted" in study["interrupted_err"]
    # the finished run was not run again, the interrupted one was run from scratch
    assert study["first"].stat().st_mtime_ns == study["first_mtime"]
    # the two depositions and the Table 2 check: the first deposition (and the check when it
    # came before the interrupted run) finished before
    assert re.search(r"3 cases, [12] finished before, [12] to run", study["stderr"]), study["stderr"]
    assert "incomplete run folder (interrupted?), running it again" in study["stderr"]
    assert (study["second"] / "result.json").exists()
    assert len(results(study)) == 2


def test_progress_lines_have_counts_elapsed_eta(study):
    line = [ln for ln in study["stderr"].splitlines() if "cases, elapsed" in ln]
    assert line and line[-1].startswith("[3/3 cases, elapsed 00:") and "ETA 00:00]" in line[-1]


def test_results_json_is_what_lammps_returned(study):
    for r in results(study):
        lmp = json.loads((r["dir"] / "lammps.json").read_text())
        assert r["source"] == "lammps computes"
        for k in ("phi", "Z", "fZ", "steps", "inserted", "atoms", "lost", "flying", "zlo", "zhi"):
            assert r["lammps"][k] == lmp[k], k
        assert r["phi"] == lmp["phi"] and r["Z"] == lmp["Z"] and r["fZ"] == lmp["fZ"]
        # compute coord/dist's global array: zmax + 1 = 21 rows (default zmax 20)
        assert len(lmp["fZ"]) == 21 and sum(lmp["fZ"]) == pytest.approx(1.0, abs=1e-12)
        assert sum(lmp["fZ_count"]) == r["python"]["n_slab"] > 0
        assert lmp["lammps_version"] >= 20250204


def test_all_deposited_none_lost(study):
    for r in results(study):
        assert r["inserted"] == N and r["natoms"] == N and r["lost"] == 0
        assert r["flying"] == 0
        assert r["lammps"]["slab"] and 0.1 < r["phi"] < 0.7


def test_python_analysis_matches_computes(study):
    # one definition: same slab, exact sphere-slab volumes on both sides (positions dumped with
    # 12 digits: 1e-8 in phi); the same contact test r_ij <= r_i + r_j and the same f(Z) bins
    # (Z >= zmax in the last one); overlaps are ~1e-9 m >> the dump's rounding
    for r in results(study):
        assert r["python"]["phi"] == pytest.approx(r["phi"], abs=1e-8)
        assert r["python"]["Z"] == pytest.approx(r["Z"], abs=1e-12)
        np.testing.assert_allclose(r["python"]["fZ"], r["fZ"], rtol=0, atol=1e-12)


def _energy_before_first_contact(run_dir, U0):
    """E_k / E_k0 of the followed particle at its last sample before its first contact, and the
    number of samples before it. A contact shows as a jump of E_k between samples (> 1 % of
    E_k0): in free flight gravity and the Coulomb field change it by ~1e-4 per sample."""
    tr = [s for s in packing.read_dump(run_dir / "tracer.dump") if s.n == 1]
    vel = np.array([[s["vx"][0], s["vy"][0], s["vz"][0]] for s in tr])
    z = np.array([s["z"][0] for s in tr])
    ek = (vel * vel).sum(axis=1) / U0 ** 2
    jumps = np.flatnonzero(np.abs(np.diff(ek)) > 0.01)
    assert len(jumps), "no contact in the tracer's record"
    # the sample interval that ends at the jump may already hold the onset of the contact (the
    # JKR snap-in pulls before the particles overlap): the free flight ends one sample earlier
    k = int(jumps[0]) - 1
    smooth = np.abs(np.diff(ek[: k + 1])).max()
    return ek[k], k, z[0] - z[k], smooth


def test_incident_particle_decelerated_by_charge(study):
    """The mechanism of the paper's Fig. 8 (and of its looser charged packings), deterministic.
    Neutral: before its first contact only gravity acts on the particle, so E_k/E_k0 =
    1 + 2 g dz / U0^2 in [1, 1 + 2 * 9.81 * 60 * 2e-6 = 1.0024] exactly. Charged (q = 480 e0):
    the 29 earlier particles are below it and the 10 later ones above; as uniform sheets of
    charge n q / L^2 (field n q / (2 eps0 L^2) on either side, independent of distance) their
    net 19 q charge does the work 19 q^2 dz / (2 eps0 L^2) = 0.11 E_k0 against it over a fall of
    dz = 52 r_p (E_k0 = m U0^2 / 2, m = 8.4e-14 kg, L = 12 um). Asserted: a loss of more than
    5 % of E_k0 (half the sheet estimate) before the first contact, with a free flight that is
    smooth (no contact hidden in it). Measured: 0.889 after 51 r_p of fall, i.e. the sheet
    estimate. Not statistical: every realisation has these charges below and above it."""
    by_q = {r["params"]["q"]: r for r in results(study)}
    assert by_q[0.0]["tracer"] == TRACER and by_q[Q]["tracer"] == TRACER
    m = 4 / 3 * math.pi * (2e-6) ** 3 * 2500
    sheet = 19 * (Q * 1.602176634e-19) ** 2 * 52 * 2e-6 / (2 * 8.8541878128e-12 * (12e-6) ** 2)
    assert sheet / (0.5 * m) == pytest.approx(0.11, abs=0.01)
    e0, k0, fall0, smooth0 = _energy_before_first_contact(by_q[0.0]["dir"], 1.0)
    eq, kq, fallq, smoothq = _energy_before_first_contact(by_q[Q]["dir"], 1.0)
    rp = 2e-6
    assert fall0 > 40 * rp and fallq > 40 * rp           # a real free flight was recorded
    assert smooth0 < 1e-3 and smoothq < 1e-3
    assert 1.0 <= e0 <= 1.0025
    assert eq < 1.0 - 0.05


def test_claims_measures_of_the_runs(study):
    """demo --claims measured every run (measures.json) and printed the claims: the incident
    particle's E_k/E_k0 before contact agrees with the bounds of the test above (neutral: gravity
    only; charged: more than 5 % lost), the whole-bed phi lies below the slab's (the rough top
    and the floor layer are looser), f(Z)'s populations and the force fractions are fractions."""
    by_q = {r["params"]["q"]: json.loads((Path(r["dir"]) / "measures.json").read_text())
            for r in results(study)}
    assert 1.0 <= by_q[0.0]["Ek_before_contact"] <= 1.0025
    assert by_q[Q]["Ek_before_contact"] < 0.95
    for r in results(study):
        m = by_q[r["params"]["q"]]
        assert m["phi_bed_top"] < m["phi_bed_2z"] and m["phi_bed_top"] < r["phi"]
        for k in ("fZ_1_2", "fZ_4_6", "Fn_inside", "Fn_tensile"):
            assert 0.0 <= m[k] <= 1.0, k
        assert np.isfinite(m["rdf_sqrt3"])
    out = study["stdout"]
    assert "g(r) peak area at r/2r_p = sqrt 3" in out and "f(Z): <Z>" in out
    # one seed: no difference is called one, no slope is printed
    assert "not resolved (fewer than 2 seeds)" in out
    assert "log-log slope of phi_0/phi - 1 vs q (paper 2): not resolved at this size" in out


def test_table2_charging_after_formation_changes_nothing(study):
    """The paper's Table 2 (F_C/F_E ~ 1e4: no contact breaks, no rearrangement). Against the
    q = 0 control (same restart, same relaxation): the same <Z> exactly and phi within 1e-4
    (measured 1.5e-6; the Coulomb forces are 4e-4 of the pull-off force here)."""
    t = pd.read_csv(study["out"] / "table2" / "table2.csv").set_index("q")
    assert list(t.index) == [0.0, 400.0]
    assert t.loc[400.0, "FC_over_FE"] > 1e4
    assert t.loc[400.0, "Z_after"] == t.loc[0.0, "Z_after"] == t.loc[400.0, "Z_before"]
    assert abs(t.loc[400.0, "phi_after"] - t.loc[0.0, "phi_after"]) < 1e-4
    assert t.loc[400.0, "paper_phi"] == 0.3247 and t.loc[0.0, "paper_Z"] == 3.2056
    # the charge was really given: the after-formation dump carries it
    after = packing.read_dump(study["out"] / "table2" / "q400" / "after.dump", last_only=True)
    assert np.allclose(after["q"], 400 * 1.602176634e-19, rtol=1e-9)


def test_reproduce_prints_tables_and_claims(study):
    out = study["stdout"]
    assert "charged after formation (the paper's Table 2" in out
    assert "NOT covered" in out and "Fig. 10" in out
    s = pd.read_csv(study["out"] / "summary.csv")
    assert list(s["q"]) == [0.0, Q] and list(s["runs"]) == [1, 1]
    assert s.loc[s["q"] == 0, "expansion"].iloc[0] == 0.0


FIGURES = ("packings", "packing_q0_s1", "packing_q480_s1", "phi_vs_q", "expansion_loglog", "rdf",
           "fZ", "force_pdf", "tracer_energy", "phi_Z_vs_Adstar", "phase_diagram_Z_phi",
           "force_network_deposition", "table2", "force_network", "force_pdf_table2",
           "conventions")


@pytest.mark.parametrize("name", FIGURES)
def test_figure_files(study, name):
    png = study["out"] / "figures" / f"{name}.png"
    img = mpimg.imread(png)
    assert img.ndim == 3 and img.shape[0] > 300 and img.shape[1] > 300
    ink = img[..., :3].min(axis=-1) < 0.9
    assert ink.mean() > 0.01                      # something is drawn
    if not name.startswith("packing_"):
        assert len(pd.read_csv(png.with_suffix(".csv"))) > 0


def test_tracer_figure_data_are_the_measured_values(study):
    """tracer_energy's right panel: one row per run with a followed particle, the value of its
    measures.json (the left panel's CSV: that particle's approach, one per charge)."""
    before = pd.read_csv(study["out"] / "figures" / "tracer_energy_before_contact.csv")
    by_q = {r["params"]["q"]: json.loads((Path(r["dir"]) / "measures.json").read_text())
            for r in results(study)}
    assert sorted(before["q"]) == sorted(by_q)
    for q, ek in zip(before["q"], before["Ek_before_contact"]):
        assert ek == pytest.approx(by_q[q]["Ek_before_contact"], rel=1e-12)
    approach = pd.read_csv(study["out"] / "figures" / "tracer_energy.csv")
    assert sorted(approach["q"].unique()) == sorted(by_q)


def test_rendered_packing_is_lammps_dump_image_coloured_by_Z(study):
    from granular_charged.paper import Z_COLORS
    for r in results(study):
        img = mpimg.imread(r["dir"] / "packing.png")[..., :3]
        ink = img.min(axis=-1) < 0.97
        assert 0.1 < ink.mean() < 0.9
        # the brightest pixels of the spheres carry the hue of a Z colour present in the bed
        Z = packing.coordination(packing.read_dump(r["dir"] / "final.dump", last_only=True))
        hue = lambda c: np.arctan2(np.sqrt(3) * (c[..., 1] - c[..., 2]),
                                   2 * c[..., 0] - c[..., 1] - c[..., 2])
        pix = hue(img[ink])
        for z in set(np.minimum(Z, len(Z_COLORS) - 1)):
            if (Z == z).sum() >= 5 and z > 0:
                h = hue(np.array(Z_COLORS[z]))
                assert (np.abs(np.angle(np.exp(1j * (pix - h)))) < 0.05).mean() > 0.002, z


def test_force_network_pairs_are_contacts_in_the_slice(study):
    r = {x["params"]["q"]: x for x in results(study)}[0.0]
    rp = r["params"]["rp"]
    fin = packing.read_dump(r["dir"] / "final.dump", last_only=True)
    df = pd.read_csv(study["out"] / "figures" / "force_network_deposition.csv")
    df = df[df["panel"].str.contains("q = 0 ")]
    assert len(df) > 5 and (df["Fn"] > 0).any() and (df["Fn"] < 0).any()
    idx = {int(i): k for k, i in enumerate(fin["id"])}
    FC = jkr_scales(rp / 2, pair_modulus(2e8, 0.33), 0.01)
    for _, row in df.iterrows():
        i, j = idx[int(row["id_i"])], idx[int(row["id_j"])]
        d = np.array([fin["x"][i] - fin["x"][j], fin["y"][i] - fin["y"][j], fin["z"][i] - fin["z"][j]])
        d[:2] -= fin.lx * np.round(d[:2] / fin.lx)
        # a JKR contact: overlap >= -delta_C (separation point)
        assert np.linalg.norm(d) <= 2 * rp + FC["deltaC"] * (1 + 1e-9)
        for k in (i, j):   # both in the slice of width 3 r_p around the box middle
            assert abs(fin["y"][k] - fin.box[1].mean()) <= 1.5 * rp + 1e-12
        assert row["Fn_over_FC"] == pytest.approx(row["Fn"] / FC["FC"], rel=1e-12)
