"""A study's outputs on a generated result set (a two-species, bipolar powder on a grid of
q_sigma x gamma, two seeds; one run unsettled, one short of particles): the tables carry the
study's name, per-species rows and the settled column; the figures' titles carry each point's
own grid values and charges, are not clipped, every axis has a unit; a force-distribution
figure is made. Also the cost estimate (settling, the charge barrier, odd values) and the
run's result line and ETA."""
import logging
import math
import sys
from pathlib import Path

import numpy as np
import pandas as pd
import pytest

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))

from granular_charged.analysis import packing, studytables  # noqa: E402
from granular_charged.figures import studyfile as sf  # noqa: E402
from granular_charged.params import DepositionParams  # noqa: E402
from granular_charged.run import estimate, logs, population  # noqa: E402

NAME = "toner test"
STUDY = {"name": NAME, "grid": {"q_sigma": [0, -5e-7], "gamma": [0.01, 0.02]},
         "species": [{"name": "polymer", "fraction": 0.7}, {"name": "silica", "fraction": 0.3}]}


def _params(q_sigma, gamma, seed, N=60):
    v = population.mixture_vars([
        {"fraction": 0.7, "size": "lognormal median=4e-6 gsd=1.25", "charge": "area sigma=-5e-7",
         "material": {"rho": 1100, "E": 5e8}},
        {"fraction": 0.3, "size": "uniform lo=2e-6 hi=3e-6", "charge": "area sigma=5e-7",
         "material": {"rho": 2200, "E": 1e9}}])
    rp = float(v.pop("rp"))
    rho, E = float(v.pop("rho")), float(v.pop("E"))
    v["q_sigma"] = f"{q_sigma:g}"
    v["q_sigma_2"] = f"{-q_sigma:g}"
    return DepositionParams(rp=rp, U0=0.5, gamma=gamma, rho=rho, E=E, N=N, seed=seed, extra=v)


def _write_run(d: Path, p: DepositionParams, rng, made: int, settled):
    """final.dump (two species in a box), forces.dump, log.lammps with a GC RESULT line."""
    d.mkdir(parents=True)
    n = made
    L = 14 * p.rp
    types = np.where(rng.random(n) < 0.7, 1, 2)
    r = np.where(types == 1, rng.uniform(3e-6, 5e-6, n), rng.uniform(2e-6, 3e-6, n))
    z = rng.uniform(0, 30 * p.rp, n)
    cols = np.column_stack([np.arange(1, n + 1), types, rng.uniform(0, L, n),
                            rng.uniform(0, L, n), z, r, np.zeros(n)])
    head = (f"ITEM: TIMESTEP\n1000\nITEM: NUMBER OF ATOMS\n{n}\nITEM: BOX BOUNDS pp pp fm\n"
            f"0 {L}\n0 {L}\n0 {40 * p.rp}\nITEM: ATOMS id type x y z radius q\n")
    (d / "final.dump").write_text(head + "\n".join(" ".join(f"{x:.9g}" for x in row)
                                                   for row in cols) + "\n")
    f = rng.normal(0.0, 0.05, 200) * 3 * math.pi * p.gamma * p.rp / 2
    ent = "\n".join(f"{i + 1} {i + 2} {2 * p.rp:.6g} {x:.6g}" for i, x in enumerate(f))
    (d / "forces.dump").write_text(f"ITEM: TIMESTEP\n1000\nITEM: NUMBER OF ENTRIES\n{len(f)}\n"
                                   f"ITEM: BOX BOUNDS pp pp fm\n0 1\n0 1\n0 1\n"
                                   f"ITEM: ENTRIES c_pa[1] c_pa[2] c_pl[1] c_pl[2]\n{ent}\n")
    extra = "" if settled is None else f" settled {settled}"
    (d / "log.lammps").write_text(f"GC RESULT steps 100000 time 1e-3 inserted {made} atoms "
                                  f"{made} lost 0 flying 2{extra} kerel 1e-3 zlo 1 zhi 2 phi "
                                  "0.3 Z 2\n")
    snap = packing.read_dump(d / "final.dump", last_only=True)
    zlo, zhi = 4 * p.rp, 24 * p.rp
    ana = packing.analyse(snap, p.rp, 4.0, 6.0)
    cls = packing.by_class(snap, None, zlo, zhi)
    return {"key": p.key(), "dir": str(d), "complete": True,
            "params": dict(vars(p), extra=dict(p.extra)), "phi": packing.phi_slab(snap, zlo, zhi),
            "Z": ana["Z"], "fZ": ana["fZ"], "zlo": zlo, "zhi": zhi,
            "python": {"phi": ana["phi"], "Z": ana["Z"], **cls},
            "protocol": "plane" if p.extra["q_sigma"] != "0" else "rain",
            "natoms": made, "lost": 0, "flying": 2, "groups": p.groups()}


@pytest.fixture(scope="module")
def results(tmp_path_factory):
    root = tmp_path_factory.mktemp("study")
    rng = np.random.default_rng(5)
    out = []
    # folders of their own (a run's key of a mixture is too long a name for some file systems)
    for qs in STUDY["grid"]["q_sigma"]:
        for g in STUDY["grid"]["gamma"]:
            for seed in (1, 2):
                p = _params(qs, g, seed)
                # one run unsettled, one short of particles, one of an old log (no field)
                settled = 0 if (qs, g, seed) == (0, 0.01, 2) else None if seed == 2 else 1
                made = 50 if (qs, g, seed) == (-5e-7, 0.02, 1) else p.N
                out.append(_write_run(root / "runs" / f"run{len(out)}", p, rng, made, settled))
    return out


# ---- tables -------------------------------------------------------------------------------------

def test_tables_carry_the_study_species_and_settled(results, tmp_path, caplog):
    with caplog.at_level(logging.WARNING):
        runs, summ = studytables.study_tables(STUDY, results, tmp_path)
    for f in ("runs.csv", "summary.csv", "classes.csv", "species.csv", "species_summary.csv"):
        t = pd.read_csv(tmp_path / f)
        assert len(t) and (t["study"] == NAME).all(), f
    r = pd.read_csv(tmp_path / "runs.csv")
    assert {"q_sigma", "gamma", "settled", "made", "N", "charges"} <= set(r.columns)
    bad = r[(r["q_sigma"] == 0) & (r["gamma"] == 0.01) & (r["seed"] == 2)]
    assert bad["settled"].tolist() == [False] and "did NOT settle" in bad["warning"].iloc[0]
    short = r[(r["q_sigma"] == -5e-7) & (r["gamma"] == 0.02) & (r["seed"] == 1)]
    assert short["made"].tolist() == [50] and "only 50 of 60" in short["warning"].iloc[0]
    assert r["settled"].isna().sum() == 3          # old logs without the field: unknown
    assert "did NOT settle" in caplog.text and "only 50 of 60" in caplog.text
    assert (r.loc[r["q_sigma"] == 0, "charges"] == "uncharged").all()
    s = pd.read_csv(tmp_path / "summary.csv")
    assert s["unsettled"].sum() == 1 and s["short"].sum() == 1 and len(s) == 4
    # per species: both species in every run, contributions adding up to the run's phi
    sp = pd.read_csv(tmp_path / "species.csv")
    assert set(sp["species_name"]) == {"polymer", "silica"}
    assert (sp.groupby("key" if "key" in sp else ["q_sigma", "gamma", "seed"])["species"]
            .nunique() == 2).all()
    tot = sp.groupby(["q_sigma", "gamma", "seed"])["phi"].sum()
    ref = {(float(x["params"]["extra"]["q_sigma"]), x["params"]["gamma"], x["params"]["seed"]):
           x["phi"] for x in results}
    for k, v in tot.items():
        assert v == pytest.approx(ref[k], rel=1e-9)
    ss = pd.read_csv(tmp_path / "species_summary.csv")
    assert len(ss) == 8 and {"phi", "Z", "number_share"} <= set(ss.columns)


# ---- figures ------------------------------------------------------------------------------------

def _texts(fig):
    return [t.get_text() for t in fig.findobj(lambda a: hasattr(a, "get_text")) if t.get_text()]


@pytest.fixture(scope="module")
def drawn(results, tmp_path_factory, monkeypatch_module):
    """Every figure of the study as (path, figure) (drawn, checked before saving)."""
    out = tmp_path_factory.mktemp("figs")
    figs = []
    real = sf._save

    def keep(fig, path, data, name):
        fig.canvas.draw()
        figs.append((Path(path), fig))
        return real(fig, path, data, name)

    monkeypatch_module.setattr(sf, "_save", keep)
    paths = sf.study_figures(STUDY, results, out)
    return out, paths, figs


@pytest.fixture(scope="module")
def monkeypatch_module():
    mp = pytest.MonkeyPatch()
    yield mp
    mp.undo()


def test_every_study_has_a_force_figure_and_csvs_with_its_name(drawn):
    out, paths, _ = drawn
    names = {p.name for p in paths}
    assert {"force_pdf.png", "phi_Z_vs_q_sigma.png", "phi_Z_vs_gamma.png", "fZ_gr.png"} <= names
    assert len([n for n in names if n.startswith("point_")]) == 4
    for p in paths:
        t = pd.read_csv(p.with_suffix(".csv"))
        assert (t["study"] == NAME).all(), p.name
    # the mixture's panels: each species' phi contribution and <Z>
    t = pd.read_csv(out / "phi_Z_vs_q_sigma.csv")
    assert {"polymer", "silica", "all"} <= set(t["species"])


def test_titles_carry_each_points_own_values_and_charges(drawn, results):
    _, _, figs = drawn
    points = {p.name: fig for p, fig in figs if p.name.startswith("point_")}
    seen = set()
    for name, fig in points.items():
        title = fig._suptitle.get_text().replace("\n", " ")
        qs = "q_sigma = 0 C/m^2" in title
        g1 = "gamma = 0.01 J/m^2" in title
        g2 = "gamma = 0.02 J/m^2" in title
        assert g1 != g2, title                      # its own gamma, one of the two
        assert qs == ("uncharged" in title), title  # the uncharged point says so ...
        assert qs != ("area" in title), title       # ... and names no area charges
        seen.add((qs, g1))
    assert len(seen) == 4
    # the titles shared by all points say neither gamma (it varies) nor "area charges"
    for p, fig in figs:
        if not p.name.startswith("point_"):
            head = fig._suptitle.get_text().split("\n")[0]
            assert "gamma 0.01" not in head and "area" not in head, head


def test_titles_not_clipped_and_axes_have_units(drawn):
    _, _, figs = drawn
    for p, fig in figs:
        r = fig.canvas.get_renderer()
        bb = fig._suptitle.get_window_extent(r)
        W, H = fig.bbox.width, fig.bbox.height
        assert bb.x0 >= 0 and bb.x1 <= W and bb.y1 <= H, p.name
        # no axis label, axes title or legend reaches past the figure's edges
        for ax in fig.axes:
            for a in (ax.xaxis.label, ax.yaxis.label, ax.title, ax.get_legend()):
                if a is not None and a.get_visible():
                    e = a.get_window_extent(r)
                    assert e.x0 >= -1 and e.y0 >= -1 and e.x1 <= W + 1 and e.y1 <= H + 1, \
                        (p.name, e)
        for ax in fig.axes:
            for lab in (ax.get_xlabel(), ax.get_ylabel()):
                assert lab and "[" in lab and "]" in lab, (p.name, lab)
    qfig = next(fig for p, fig in figs if p.name == "phi_Z_vs_q_sigma.png")
    assert all("q_sigma [C/m^2]" == ax.get_xlabel() for ax in qfig.axes)


def test_figures_of_points_without_a_slab(results, tmp_path):
    """A point whose beds were too thin for the analysis slab (phi, <Z> None) is drawn as a gap,
    the other figures as usual."""
    import copy
    thin = copy.deepcopy(results)
    for r in thin:
        if r["params"]["gamma"] == 0.01:
            r.update(phi=None, Z=None, zlo=None, zhi=None, fZ=[])
    paths = sf.study_figures(STUDY, thin, tmp_path)
    assert {"force_pdf.png", "phi_Z_vs_q_sigma.png"} <= {p.name for p in paths}


def test_study_label_names_only_what_all_runs_share(results):
    lab = sf.study_label(STUDY, results)
    assert lab.startswith(NAME) and "gamma" not in lab and "area" not in lab and "N = 60" in lab
    same = [r for r in results if r["params"]["gamma"] == 0.02 and
            r["params"]["extra"]["q_sigma"] != "0"]
    lab = sf.study_label(STUDY, same)
    assert "gamma 0.02 J/m^2" in lab and "area sigma -5e-07" in lab


def test_covaried_parameters_are_one_axis(results, tmp_path):
    """Both species' charge densities varied together: phi against q_sigma has one series per
    gamma (q_sigma_2 is not a series of its own)."""
    d = dict(STUDY, grid={"gamma": [0.01, 0.02],
                          "together": {"q_sigma": [0, -5e-7], "q_sigma_2": [0, 5e-7]}})
    assert studytables.axis_groups(d) == [["gamma"], ["q_sigma", "q_sigma_2"]]
    sf.study_figures(d, results, tmp_path)
    t = pd.read_csv(tmp_path / "phi_Z_vs_q_sigma.csv")
    allp = t[(t["species"] == "all") & (t["measure"] == "phi")]
    assert "q_sigma_2" not in t.columns and len(allp) == 4 and allp["runs"].eq(2).all()


def test_units_of_grid_parameters():
    assert studytables.axis_label("q_sigma") == "q_sigma [C/m^2]"
    assert studytables.axis_label("q_sigma_2") == "q_sigma_2 [C/m^2]"
    assert studytables.axis_label("U0") == "U0 [m/s]"
    assert studytables.axis_label("nu") == "nu [dimensionless]"
    assert studytables.grid_names({"grid": {"a": [1], "together": {"b": [1], "c": [2]}}}) == \
        ["a", "b", "c"]


# ---- the result line, the status, the ETA -----------------------------------------------------

def test_result_line_with_and_without_settled(tmp_path):
    old = "GC RESULT steps 10 time 1 inserted 5 atoms 5 lost 0 flying 0 kerel 1 zlo 1 zhi 0 phi none Z none"
    r = logs.parse_result_line("x\n" + old + "\n")
    assert r["inserted"] == 5 and r["phi"] is None and "settled" not in r
    new = old.replace("flying 0", "flying 3 settled 0")
    assert logs.parse_result_line(new)["settled"] == 0
    (tmp_path / "log.lammps").write_text(new + "\n")
    st = logs.run_status({"params": {"N": 5}, "dir": str(tmp_path)})
    assert st["settled"] is False and not st["short"] and "did NOT settle" in st["warning"]
    st = logs.run_status({"params": {"N": 8}, "inserted": 5, "settled": 1})
    assert st["settled"] is True and st["short"] and "only 5 of 8" in st["warning"]
    assert logs.run_status({"params": {"N": 5}, "inserted": 5})["warning"] is None


def test_eta_counts_the_settling():
    p = DepositionParams(N=100, extra={"L_rp": "14", "inject": "rain", "gap_rp": "1"})
    pl = estimate.run_plan(p)
    step = 58 * pl["n_i"]
    line = f"GC PROGRESS 58 / 100 particles, step {step}, elapsed 30 s, eta 22 s, kerel 0.1"
    eta = logs.eta_seconds(line, pl)
    # the deck's eta counts the 42 particles left only (22 s); the settling is most of the rest
    assert eta > 5 * 22
    assert logs.eta_seconds("GC SETTLE step 5", pl) is None and logs.eta_seconds(line, None) is None


# ---- the cost estimate --------------------------------------------------------------------------

def test_estimate_includes_the_settling():
    p = DepositionParams(N=100, extra={"L_rp": "14", "inject": "rain", "gap_rp": "1"})
    pl = estimate.plan(p)
    assert pl["settle_steps"] == pytest.approx(estimate.settle_steps_rp(p) * pl["unit"])
    assert pl["settle_steps"] >= 30 * pl["unit"]       # the fit: tens of r_p / U_0 at least
    # slower, larger particles (g r_p / U_0^2 ten times the demo's) settle ten times longer
    big = DepositionParams(N=100, rp=5e-6, U0=0.5, extra={"L_rp": "14", "inject": "plane"})
    assert estimate.settle_steps_rp(big) == pytest.approx(
        min(1000.0, 10 * estimate.settle_steps_rp(p)), rel=1e-9)
    assert pl["steps"] == pytest.approx(pl["inject_steps"] + pl["fall_steps"] + pl["settle_steps"])
    # for a small bed the last fall and the settling are most of the work
    assert pl["work"] > 2 * pl["n_i"] * 100 ** 2 / 2
    assert "of them the last fall and the settling" in estimate.describe(estimate.estimate([p]))


def test_estimate_warns_when_the_charge_turns_particles_back():
    weak = DepositionParams(q=100.0, N=200, extra={"L_rp": "14", "inject": "plane"})
    strong = DepositionParams(q=2000.0, N=200, extra={"L_rp": "14", "inject": "plane"})
    assert estimate.barrier(weak) is None
    b = estimate.barrier(strong)
    assert b is not None and 1 <= b["k"] < 200 and b["Estar"] > 1
    e_weak, e_strong = estimate.estimate([weak]), estimate.estimate([strong])
    assert not e_weak["turned_back"] and e_strong["turned_back"][0][1] == b["k"]
    text = estimate.describe(e_strong)
    assert "turn the particles back" in text and f"~{b['k']} of 200" in text
    # the run stops there: its estimate counts the particles that arrive
    assert estimate.plan(strong)["N_dep"] == b["k"] < estimate.plan(weak)["N_dep"]
    # a bipolar powder of zero net charge has no barrier; a net one of either sign has
    assert estimate.barrier(_params(0.0, 0.02, 1)) is None
    tv = _params(-2e-5, 0.02, 1)
    tv.extra["q_sigma_2"] = "0"
    assert estimate.barrier(tv) is not None


@pytest.mark.parametrize("field,value", [("N", 0), ("N", -5), ("U0", 0.0), ("U0", -1.0),
                                         ("U0", float("nan")), ("rp", 0.0), ("E", 0.0),
                                         ("rho", float("inf")), ("q", float("nan"))])
def test_estimate_never_raises(field, value):
    p = DepositionParams(N=50)
    object.__setattr__(p, field, value) if hasattr(p, "__dataclass_fields__") else None
    setattr(p, field, value)
    est = estimate.estimate([p])
    assert isinstance(estimate.describe(est), str)
    assert len(estimate.cpu_seconds([p])) == 1


@pytest.mark.parametrize("extra", [{"L_rp": "abc"}, {"species": "2", "frac": "-1"},
                                   {"r_dist": "lognormal", "rp_gsd": "1"}, {"gap_rp": "nan"},
                                   {"settle_max": "-3"}, {"q_dist": "area", "q_sigma": "x"}])
def test_estimate_never_raises_on_odd_deck_values(extra):
    p = DepositionParams(N=50)
    p.extra.update(extra)            # past the checks of DepositionParams: whatever comes
    est = estimate.estimate([p])
    assert isinstance(estimate.describe(est), str)
    assert len(estimate.cpu_seconds([p])) == 1
