"""A study's LAMMPS runs share the cores: Runner.at_most keeps them to `jobs` at a time, whichever
threads start them, and Study starts the Table 2 check as soon as its packing is there, beside
the depositions still to come. LAMMPS is replaced by a fake child process (no build needed):
what is tested is the scheduling, not a run."""
import json
import subprocess
import threading
import time
from concurrent.futures import ThreadPoolExecutor
from pathlib import Path

import pytest

from granular_charged import runner as runner_mod
from granular_charged.params import DepositionParams
from granular_charged.runner import RESULT_VERSION, RunError, Runner, write_json
from granular_charged.study import Study


class FakeBuild:
    path = Path("/nonexistent")
    can_render = False
    capabilities = {"coul/fmm": True, "packing computes": True}

    @staticmethod
    def child_env():
        return {}


class Clock:
    """Records when each fake LAMMPS run starts and ends, and the most at once."""
    def __init__(self):
        self.lock = threading.Lock()
        self.active = self.peak = 0
        self.spans = {}

    def run(self, name: str, seconds: float):
        with self.lock:
            self.active += 1
            self.peak = max(self.peak, self.active)
            t0 = time.monotonic()
        time.sleep(seconds)
        with self.lock:
            self.active -= 1
            self.spans[name] = (t0, time.monotonic())


@pytest.fixture
def clock(monkeypatch):
    """subprocess.run of the runner replaced: 0.05 s, then lammps.json in the run's folder."""
    c = Clock()

    def fake_run(cmd, **kw):
        workdir = Path(cmd[cmd.index("--kind") - 1])
        c.run(workdir.name, 0.05)
        (workdir / "lammps.json").write_text(json.dumps(
            {"phi_before": 0.4, "phi_after": 0.4, "Z_before": 4.0, "Z_after": 4.0}))
        return subprocess.CompletedProcess(cmd, 0, "", "")
    monkeypatch.setattr(runner_mod.subprocess, "run", fake_run)
    return c


def test_at_most_keeps_the_runs_to_jobs(tmp_path, clock):
    r = Runner(FakeBuild())
    with r.at_most(2), ThreadPoolExecutor(6) as ex:
        list(ex.map(lambda k: r.run_deck("in.deposition", tmp_path / f"w{k}", {}), range(12)))
    assert len(clock.spans) == 12
    assert clock.peak == 2       # six threads, two runs at a time (1 would mean no overlap)
    # outside at_most there is no limit again
    with ThreadPoolExecutor(6) as ex:
        list(ex.map(lambda k: r.run_deck("in.deposition", tmp_path / f"v{k}", {}), range(6)))
    assert clock.peak == 6


def test_runs_waiting_for_a_slot_do_not_start_after_a_stop(tmp_path, clock):
    r = Runner(FakeBuild())
    with pytest.raises(KeyboardInterrupt), ThreadPoolExecutor(4) as ex:
        with r.at_most(1):
            futs = [ex.submit(r.run_deck, "in.deposition", tmp_path / f"w{k}", {})
                    for k in range(4)]
            time.sleep(0.02)          # the first run has the slot, three wait
            raise KeyboardInterrupt
    outcomes = [f.exception() for f in futs]
    assert sum(e is None for e in outcomes) == 1
    assert all(isinstance(e, RunError) and "not started" in str(e) for e in outcomes if e)
    assert len(clock.spans) == 1


class SlowDepositions(Runner):
    """Depositions that hold a slot for a while (charged ones longer) and write a result."""
    def deposition(self, p, root, force=False, tracer=0):
        wd = self.workdir(p, root)
        wd.mkdir(parents=True, exist_ok=True)
        with self._slots:
            self.clock.run(wd.name, 0.3 if p.q else 0.1)
        res = {"version": RESULT_VERSION, "complete": True, "key": p.key(), "params": vars(p),
               "groups": [], "phi": 0.4, "Z": 4.0, "fZ": [], "inserted": p.N, "natoms": p.N,
               "lost": 0, "flying": 0, "wall_s": 0.1}
        write_json(wd / "result.json", res)
        return dict(res, dir=str(wd), skipped=False)


class SixRuns(Study):
    def params(self, have_fmm):
        return [DepositionParams(q=q, N=10, seed=s) for q in (0.0, 400.0) for s in (1, 2, 3)]


def test_table2_check_starts_beside_the_remaining_depositions(tmp_path, clock):
    r = SlowDepositions(FakeBuild())
    r.clock = clock
    study = SixRuns(out=tmp_path, jobs=2, progress=False, table2_qs=(0.0, 400.0))
    results, rows = study._run_all(r, study.params(True), tmp_path, have_fmm=True)
    assert len(results) == 6 and [row["q"] for row in rows] == [0.0, 400.0]
    assert (tmp_path / "table2" / "table2.csv").exists()
    assert not list(tmp_path.glob("table2-s*"))          # the first seed's packing only
    last_deposition_end = max(end for name, (t0, end) in clock.spans.items() if "_N10_" in name)
    first_check_start = min(t0 for name, (t0, end) in clock.spans.items() if name.startswith("q"))
    # two slots, 3 x 0.1 s and 3 x 0.3 s of depositions: however the slots are taken, the check
    # starts before the last deposition ends (at the latest when only that one is left)
    assert first_check_start < last_deposition_end      # fails when the check waits for all
    assert clock.peak == 2
