"""Several targets (issue 41): `track_multi` against the CLI's `track --targets auto` (bit for
bit, PMB and GNN, with and without truth, settings, calibration, detections),
`simulate_people` against the CLI's `simulate-walk --walkers` and `--path` files, the score's GOSPA per scan
against Stone Soup's `GOSPAMetric` (an independent implementation) and its label switches and
cardinality error recomputed from Stone Soup's assignment and the counts, and bad input."""

from __future__ import annotations

import datetime
import json

import numpy as np
import pytest
import scatterloc as sl
from conftest import assert_bitwise
from stonesoup.metricgenerator.ospametric import GOSPAMetric
from stonesoup.types.state import State

T0 = datetime.datetime(2026, 12, 7)
TX2 = {"name": "Tx2", "position_m": [14.0, 4.0], "power_dbm": 37.0, "gain_dbi": 9.0,
       "pattern": {"kind": "omni"}}


def people_scenario(cli) -> str:
    """sensors2019 with a second transmitter (8 links), written to s.json."""
    doc = cli.json("preset", "sensors2019")
    doc["transmitters"].append(TX2)
    return cli.write("s.json", doc)


def walk(cli, seed: int, walkers: int = 3, *extra: str) -> tuple[str, str]:
    d = f"w{seed}"
    cli.run("simulate-walk", "--scenario", "s.json", "--out-dir", d, "--walkers", str(walkers),
            "--seed", str(seed), *extra)
    return f"{d}/measurements.json", f"{d}/truth.json"


@pytest.mark.parametrize("seed", [2, 5])
def test_simulate_people_equals_cli(cli, seed):
    people_scenario(cli)
    s = sl.Scenario(str(cli.cwd / "s.json"))
    mpath, tpath = walk(cli, seed)
    m, t = sl.simulate_people(s, 3, seed=seed)
    assert_bitwise(m, cli.file(mpath))
    assert_bitwise(t, cli.file(tpath))
    assert len(t["targets"]) == 101 and len(m["raw_steps"]) == 100
    assert all(len(scan) == 3 for scan in t["targets"])
    # Every keyword, as the CLI's flags.
    kw = dict(duration_s=3.0, dt_s=0.05, process_noise=0.2, detection_probability=0.7, clutter=2.0)
    mpath, tpath = walk(cli, seed + 10, 2, "--duration", "3", "--dt", "0.05", "--process-noise", "0.2",
                        "--detection-probability", "0.7", "--false-alarms", "2")
    m, t = sl.simulate_people(s, 2, seed=seed + 10, **kw)
    assert_bitwise(m, cli.file(mpath))
    assert_bitwise(t, cli.file(tpath))


def test_simulate_people_drawn_paths_equal_cli(cli):
    people_scenario(cli)
    s = sl.Scenario(str(cli.cwd / "s.json"))
    paths = np.array([[1.0, 2.0, 8.5, 7.25], [-0.5, 6.0, 9.0, 1.5], [4.0, 4.0, 4.0, 4.0]])
    flags = [a for p in paths for a in ("--path", ",".join(repr(float(x)) for x in p))]
    cli.run("simulate-walk", "--scenario", "s.json", "--out-dir", "d", "--seed", "6", *flags)
    cm, ct = cli.file("d/measurements.json"), cli.file("d/truth.json")
    # A numpy (n, 4) array, a list of 4-tuples, and with walkers equal to the rows: the CLI's files.
    for kw in (dict(paths=paths), dict(paths=[tuple(p) for p in paths.tolist()]),
               dict(walkers=3, paths=paths)):
        m, t = sl.simulate_people(s, seed=6, **kw)  # type: ignore[arg-type]
        assert_bitwise(m, cm)
        assert_bitwise(t, ct)
    first, last = t["targets"][0], t["targets"][-1]
    assert [x["label"] for x in first] == [0, 1, 2]
    for i, p in enumerate(paths):
        assert np.allclose(first[i]["state"][:2], p[:2], rtol=0, atol=1e-12)
        assert np.allclose(last[i]["state"][:2], p[2:], rtol=0, atol=1e-12)
    # Bad paths are named.
    for kw, field in ((dict(paths=np.zeros((6, 4))), "paths"), (dict(paths=[]), "paths"),
                      (dict(paths=np.zeros((2, 3))), "paths"),
                      (dict(paths=[[0.0, 1.0, 2.0, float("nan")]]), "paths[0].y1"),
                      (dict(paths=[[0.0, 1.0, 2.0, 1e9]]), "paths[0].y1"),
                      (dict(walkers=2, paths=paths), "walkers"), (dict(), "walkers")):
        with pytest.raises(sl.ScatterlocError) as e:
            sl.simulate_people(s, seed=6, **kw)  # type: ignore[arg-type]
        assert e.value.field == field, (kw, e.value.field, str(e.value))


def test_track_multi_equals_cli(cli):
    people_scenario(cli)
    s = sl.Scenario(str(cli.cwd / "s.json"))
    mpath, tpath = walk(cli, 3)
    m_doc, t_doc = cli.file(mpath), cli.file(tpath)
    base = ["track", "--scenario", "s.json", "--measurements", mpath, "--targets", "auto"]
    for method in ("pmb", "gnn"):
        doc = cli.json(*base, "--method", method)
        assert "score" not in doc
        for m in (m_doc, cli.cwd / mpath, str(cli.cwd / mpath)):
            mt = sl.track_multi(s, m, method=method)
            assert_bitwise(mt.to_dict(), doc)
        assert mt.score is None and mt.method == method and len(mt) == len(doc["t_s"])
        scored = cli.json(*base, "--method", method, "--truth", tpath)
        for t in (t_doc, cli.cwd / tpath):
            mt = sl.track_multi(s, m_doc, method=method, truth=t)
            assert_bitwise(mt.to_dict(), scored)
        assert mt.score == scored["score"]
        # The arrays: the document's targets in long format.
        rows = [(k, x) for k, scan in enumerate(doc["targets"]) for x in scan]
        assert mt.scan.dtype == np.int64 and mt.scan.tolist() == [k for k, _ in rows]
        assert mt.label.tolist() == [x["label"] for _, x in rows]
        assert mt.states.shape == (len(rows), 4) and mt.states.tolist() == [x["state"] for _, x in rows]
        assert mt.covariances.shape == (len(rows), 4, 4)
        assert mt.covariances.tolist() == [x["covariance"] for _, x in rows]
        assert mt.existence.tolist() == [x["existence"] for _, x in rows]
        assert mt.count.tolist() == [len(scan) for scan in doc["targets"]]
        assert mt.labels.tolist() == [x["label"] for x in doc["tracks"]]
        assert mt.tracks == doc["tracks"] and mt.t.tolist() == doc["t_s"]
        assert mt.static_removed.tolist() == doc["static_removed"]
    # Every setting, as the CLI's flags (the window in ns there).
    doc = cli.json(*base, "--method", "gnn", "--detection-probability", "0.8", "--clutter", "3",
                   "--clutter-window-ns", "50", "--birth-rate", "0.02", "--truth", tpath,
                   "--gospa-c", "2")
    mt = sl.track_multi(s, m_doc, method="gnn", detection_probability=0.8, clutter=3.0,
                        clutter_window_s=50 * 1e-9, birth_rate=0.02, truth=t_doc, gospa_c=2.0)
    assert_bitwise(mt.to_dict(), doc)


def test_track_multi_calibration_and_detections_equal_cli(cli):
    people_scenario(cli)
    s = sl.Scenario(str(cli.cwd / "s.json"))
    # One person with static paths: the single-target walk and its calibration.
    cli.run("simulate-walk", "--scenario", "s.json", "--out-dir", "one", "--duration", "4")
    cli.run("calibrate", "--scenario", "s.json", "--snapshots", "one/calibration_snapshots.json",
            "--out", "cal.json")
    doc = cli.json("track", "--scenario", "s.json", "--measurements", "one/measurements.json",
                   "--calibration", "cal.json", "--targets", "auto")
    assert sum(doc["static_removed"]) > 0
    cal = sl.calibrate(s, cli.file("one/calibration_snapshots.json")["snapshots"])
    for c in (cal, cli.file("cal.json"), cli.cwd / "cal.json"):
        mt = sl.track_multi(s, cli.cwd / "one/measurements.json", calibration=c)
        assert_bitwise(mt.to_dict(), doc)

    # Detections (JSON lines) of three people: `track --detections --targets auto`.
    m, _ = sl.simulate_people(s, 3, duration_s=3.0, seed=4)
    links = s.link_indices.tolist()
    lines = [{"timestamp": round(k * m["dt_s"], 12), "tx": tx, "rx": rx, "unit": "s",
              "delay": [e[0] for e in step[p]]}
             for k, step in enumerate([m["initial_snapshot"], *m["raw_steps"]])
             for p, (tx, rx) in enumerate(links) if step[p]]
    det = sl.Detections(lines)
    sl.write_detections(cli.cwd / "d.jsonl", det)
    for q, extra in ((None, []), (0.3, ["--process-noise", "0.3"])):
        doc = cli.json("track", "--scenario", "s.json", "--detections", "d.jsonl", "--targets",
                       "auto", *extra)
        assert_bitwise(sl.track_multi(s, det, process_noise=q).to_dict(), doc)


def stonesoup_gospa(truth: list, est: list, c: float) -> tuple[dict, list]:
    metric = GOSPAMetric(c=c, p=2.0)
    states = lambda pts: [State(np.asarray(q[:2], float).reshape(2, 1), timestamp=T0) for q in pts]
    value, assignment = metric.compute_gospa_metric(states(est), states(truth))
    return value.value, list(assignment)


@pytest.mark.parametrize("method,c", [("pmb", 1.0), ("gnn", 1.0), ("pmb", 0.3)])
def test_score_equals_stone_soup(cli, method, c):
    people_scenario(cli)
    s = sl.Scenario(str(cli.cwd / "s.json"))
    m, truth = sl.simulate_people(s, 4, duration_s=5.0, clutter=8.0, seed=7)
    mt = sl.track_multi(s, m, method=method, truth=truth, gospa_c=c)
    score = mt.score
    assert score is not None and score["c_m"] == c
    est = mt.to_dict()["targets"]
    assert len(est) == len(truth["targets"]) == len(score["gospa_m"])
    last: dict[int, int] = {}
    switches = 0
    for k, (tk, ek) in enumerate(zip(truth["targets"], est)):
        x = [t["state"] for t in tk]
        y = [e["state"] for e in ek]
        if not x and not y:
            assert score["gospa_m"][k] == 0.0
            continue
        want, assign = stonesoup_gospa(x, y, c)
        for ours, theirs in (("gospa_m", "distance"), ("localisation_m2", "localisation"),
                             ("missed_m2", "missed"), ("false_m2", "false")):
            assert score[ours][k] == pytest.approx(want[theirs], rel=1e-9, abs=1e-12), (k, ours)
        # Label switches from Stone Soup's assignment (pairs closer than c).
        for i, j in enumerate(assign if y else []):
            if j >= 0 and np.hypot(x[i][0] - y[j][0], x[i][1] - y[j][1]) < c:
                label = ek[j]["label"]
                if last.get(tk[i]["label"], label) != label:
                    switches += 1
                last[tk[i]["label"]] = label
    assert score["switches"] == switches
    card = np.abs(mt.count - np.array([len(t) for t in truth["targets"]]))
    assert score["mean_cardinality_error"] == pytest.approx(card.mean(), rel=1e-12)
    assert score["mean_gospa_m"] == pytest.approx(np.mean(score["gospa_m"]), rel=1e-12)


def test_track_multi_bad_input(cli):
    people_scenario(cli)
    s = sl.Scenario(str(cli.cwd / "s.json"))
    m, truth = sl.simulate_people(s, 2, duration_s=1.0, seed=1)
    with pytest.raises(sl.ScatterlocError) as e:
        sl.track_multi(s, m, method="jpda")  # type: ignore[arg-type]
    assert e.value.kind == "UnknownFilter" and "method" in e.value.field
    for p in (1.5, 0.0, float("nan")):
        with pytest.raises(sl.ScatterlocError) as e:
            sl.track_multi(s, m, detection_probability=p)
        assert e.value.field == "detection_probability" and e.value.kind == "OutOfRange"
    # A measurements file with steps (one delay per link), not raw_steps.
    steps = {"dt_s": 0.1, "process_noise": 0.5, "initial_state": [4.0, 1.0, 0.0, 0.0],
             "initial_covariance": np.diag([0.1, 0.1, 0.01, 0.01]).tolist(),
             "steps": [[3e-8] * s.link_count] * 3}
    with pytest.raises(sl.ScatterlocError) as e:
        sl.track_multi(s, steps)
    assert e.value.field == "raw_steps" and e.value.kind == "InvalidFile"
    # Truth of the wrong shape: a state of 3 values, a scan that is not a list.
    bad = json.loads(json.dumps(truth))
    bad["targets"][1][0]["state"] = [1.0, 2.0, 3.0]
    with pytest.raises(sl.ScatterlocError) as e:
        sl.track_multi(s, m, truth=bad)
    assert e.value.kind == "Parse" and "targets[1][0].state" in str(e.value)
    bad = dict(truth, targets=[1.0] * len(truth["targets"]))
    with pytest.raises(sl.ScatterlocError) as e:
        sl.track_multi(s, m, truth=bad)
    assert e.value.kind == "Parse" and "targets[0]" in str(e.value)
    with pytest.raises(sl.ScatterlocError) as e:
        sl.track_multi(s, m, gospa_c=2.0)
    assert e.value.field == "gospa_c"
    with pytest.raises(sl.ScatterlocError) as e:
        sl.track_multi(s, m, truth=truth, gospa_c=0.0)
    assert "c" in (e.value.field or "")
    with pytest.raises(sl.ScatterlocError) as e:
        sl.track_multi(s, m, process_noise=0.3)
    assert e.value.field == "process_noise"
    with pytest.raises(sl.ScatterlocError) as e:
        sl.track_multi(s, [[1e-8]] * 3)  # type: ignore[arg-type]
    assert e.value.field == "measurements"
    with pytest.raises(sl.ScatterlocError) as e:
        sl.track_multi(s, m, calibration={"links": []})
    assert e.value.field is not None or e.value.kind == "Parse"


def test_simulate_people_bad_input():
    s = sl.Scenario.preset("sensors2019")
    for kw, field in ((dict(walkers=0), "walkers"), (dict(walkers=6), "walkers"),
                      (dict(walkers=2, duration_s=-1.0), "duration_s"),
                      (dict(walkers=2, duration_s=1e9), "steps"),
                      (dict(walkers=2, detection_probability=1.0), "detection_probability")):
        with pytest.raises(sl.ScatterlocError) as e:
            sl.simulate_people(s, **kw)  # type: ignore[arg-type]
        assert e.value.field == field, (kw, e.value.field)
    with pytest.raises(sl.ScatterlocError) as e:
        sl.simulate_people(s, 2, dt_s=0.0)
    assert "dt" in (e.value.field or "")
