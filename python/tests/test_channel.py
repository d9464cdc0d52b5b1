"""The channel front end against the CLI's `cir simulate`, `cir estimate` and `cir track` (bit for
bit; with and without a recording of the empty area, every front-end and tracker setting),
`Recording` built from arrays and its checks, the `.npz` round trip through
`write_recording`/`read_recording` and `numpy.load` (docs/recording.md), `estimate` on one link
against that link's entries of EST.json, the dtypes and shapes of `Paths`, the track's segments
(C11) against its states, and errors named by the core's request fields."""

from __future__ import annotations

import json
import math
from types import SimpleNamespace

import numpy as np
import pytest

import scatterloc as sl
from conftest import Cli, assert_bitwise

DT = "0.05"
DURATION = "4"
C = 299_792_458.0
FORTRAN = (
    "bug: a Fortran-ordered (F-contiguous, e.g. a transposed) numpy array is read in memory "
    "(column-major) order instead of its logical order: {where} take the data with "
    "rust-numpy's PyArray::to_vec(), which accepts any contiguous array and copies its raw "
    "buffer; only non-contiguous arrays go through the (correct) as_array() iteration. Same "
    "root cause in python/src/convert.rs f64_array (e.g. Scenario.delays(points.T.copy().T) "
    "differs from Scenario.delays(points))"
)


def assert_same_bits(a: np.ndarray, b: np.ndarray) -> None:
    """Same dtype, shape and bytes (NaN payloads and signed zeros included)."""
    a, b = np.asarray(a), np.asarray(b)
    assert a.dtype == b.dtype, (a.dtype, b.dtype)
    assert a.shape == b.shape, (a.shape, b.shape)
    assert np.ascontiguousarray(a).tobytes() == np.ascontiguousarray(b).tobytes()


def est_rows(est: dict, link: int | None = None) -> list[tuple[int, int, dict]]:
    """EST.json's estimates in long format: (snapshot, link, entry), snapshot-major."""
    return [
        (s, l, e)
        for s, per in enumerate(est["estimates"])
        for l, es in enumerate(per)
        if link is None or l == link
        for e in es
    ]


# --------------------------------------------------------------------------------------------
# A short simulated walk (81 snapshots x 4 links x 241 bins), once per seed, by the CLI and by
# the package.


@pytest.fixture(scope="module", params=[1, 2, 3])
def sim(request, tmp_path_factory) -> SimpleNamespace:
    seed = request.param
    cli = Cli(tmp_path_factory.mktemp(f"cir{seed}"))
    s = sl.Scenario.preset("sensors2019")
    cli.write("s.json", s.to_dict())
    cli.run(
        "cir", "simulate", "--scenario", "s.json", "--out-dir", "sim", "--dt", DT,
        "--duration", DURATION, "--seed", str(seed),
    )
    # Without --calibration: a recursive background of the walk itself.
    cli.run("cir", "estimate", "--scenario", "s.json", "--cir", "sim/recording.npz", "--out", "est.json")
    cli.run(
        "cir", "estimate", "--scenario", "s.json", "--cir", "sim/recording.npz",
        "--calibration", "sim/calibration.npz", "--out", "est_cal.json",
    )
    rec, cal, truth = sl.simulate_recording(s, dt=float(DT), duration=float(DURATION), seed=seed)
    progress: list[tuple[int, int]] = []
    paths = sl.estimate_recording(s, rec, progress=lambda d, t: progress.append((d, t)))
    paths_cal = sl.estimate_recording(s, rec, calibration=cal)
    return SimpleNamespace(
        seed=seed, cli=cli, s=s, rec=rec, cal=cal, truth=truth, est=cli.file("est.json"),
        paths=paths, progress=progress, est_cal=cli.file("est_cal.json"), paths_cal=paths_cal,
    )


# --------------------------------------------------------------------------------------------
# Recording from arrays


def small_cfr(seed: int = 0, S: int = 5, P: int = 2, N: int = 8):
    rng = np.random.default_rng(seed)
    t = 0.1 * np.arange(S)
    links = np.array([[0, 2], [0, 0]], dtype=np.int64)[:P]
    cfr = rng.normal(size=(S, P, N)) + 1j * rng.normal(size=(S, P, N))
    freq = (np.arange(N) - (N - 1) / 2) * 1e6
    return t, links, cfr, freq


def test_recording_cfr_from_arrays():
    t, links, cfr, freq = small_cfr()
    nv = np.array([1e-3, 2e-3])
    r = sl.Recording(t, links, cfr=cfr, freq_hz=freq, noise_var=nv)
    assert r.layout == "cfr"
    assert len(r) == 5
    assert_same_bits(r.t, t)
    assert_same_bits(r.links, links)
    assert_same_bits(r.samples, cfr)
    assert_same_bits(r.freq_hz, freq)
    assert_same_bits(r.noise_var, nv)
    assert r.taps is None
    # Other dtypes are converted exactly: complex64 samples, int32 links, lists.
    r32 = sl.Recording(list(t), links.astype(np.int32), cfr=cfr.astype(np.complex64), freq_hz=list(freq))
    assert r32.samples.dtype == np.complex128 and r32.links.dtype == np.int64
    assert_same_bits(r32.samples, cfr.astype(np.complex64).astype(np.complex128))
    assert_same_bits(r32.links, links)
    assert r32.noise_var is None


def test_recording_cir_from_arrays():
    t, links, cir, _ = small_cfr(1)
    r = sl.Recording(t, links, cir=cir, tap0_s=-4e-9, tap_spacing_s=1e-9)
    assert r.layout == "cir"
    assert r.taps == (-4e-9, 1e-9)
    assert r.freq_hz is None and r.noise_var is None
    assert_same_bits(r.samples, cir)
    assert r.samples.shape == (5, 2, 8)


def test_recording_between():
    t, links, cfr, freq = small_cfr(S=10)
    r = sl.Recording(t, links, cfr=cfr, freq_hz=freq, noise_var=[1.0, 2.0])
    b = r.between(0.2, 0.5)  # inclusive at both ends
    keep = (t >= 0.2) & (t <= 0.5)
    assert keep.sum() == 4 and len(b) == 4
    assert_same_bits(b.t, t[keep])
    assert_same_bits(b.samples, cfr[keep])
    assert_same_bits(b.links, links)
    assert_same_bits(b.freq_hz, freq)
    assert_same_bits(b.noise_var, np.array([1.0, 2.0]))
    assert len(r.between(t[3], t[3])) == 1  # t[3] = 0.30000000000000004
    assert len(r.between(-1.0, 100.0)) == 10
    with pytest.raises(sl.ScatterlocError) as e:
        r.between(5.0, 6.0)
    assert e.value.field == "t"
    with pytest.raises(sl.ScatterlocError) as e:
        r.between(0.5, 0.2)
    assert e.value.field == "t"


def test_recording_synchronized(tmp_path):
    t, links, cfr, freq = small_cfr(S=6)
    assert sl.Recording(t, links, cfr=cfr, freq_hz=freq).synchronized is None
    for flag in (True, False):
        r = sl.Recording(t, links, cfr=cfr, freq_hz=freq, synchronized=flag)
        assert r.synchronized is flag
        assert r.between(0.1, 0.3).synchronized is flag
        p = tmp_path / f"s{flag}.npz"
        sl.write_recording(p, r)
        assert sl.read_recording(p).synchronized is flag
        with np.load(p) as z:
            assert "synchronized" in z.files
            assert z["synchronized"].dtype == np.bool_ and bool(z["synchronized"]) is flag


def test_recording_and_estimate_fortran_order():
    t, links, cfr, freq = small_cfr(6)
    r = sl.Recording(t, links, cfr=np.asfortranarray(cfr), freq_hz=freq)
    assert_same_bits(r.samples, cfr)
    freq, _, _, nv, h = two_paths(1, S=4)
    c = sl.estimate(np.ascontiguousarray(h), freq_hz=freq, noise_var=nv)
    f = sl.estimate(np.asfortranarray(h), freq_hz=freq, noise_var=nv)
    assert_same_bits(f.delay, c.delay)


@pytest.mark.parametrize(
    "change, field",
    [
        # wrong shapes
        (lambda a: a.update(cfr=a["cfr"][:, :1]), "cfr"),
        (lambda a: a.update(cfr=a["cfr"][0]), "cfr"),
        (lambda a: a.update(freq_hz=a["freq_hz"][:-1]), "cfr"),
        (lambda a: a.update(links=np.array([[0, 0, 0], [0, 1, 0]])), "links"),
        (lambda a: a.update(noise_var=[1.0, 2.0, 3.0]), "noise_var"),
        # t not strictly increasing (the core names the file's array)
        (lambda a: a.update(t=np.array([0.0, 0.1, 0.1, 0.3, 0.4])), "t_s"),
        (lambda a: a.update(t=np.array([0.0, 0.2, 0.1, 0.3, 0.4])), "t_s"),
        # missing or misplaced layout arrays
        (lambda a: a.pop("freq_hz"), "freq_hz"),
        (lambda a: a.update(tap0_s=0.0), "tap0_s"),
        (lambda a: a.pop("cfr"), "cfr"),
        (lambda a: a.update(cir=a["cfr"]), "cfr"),
        (lambda a: a.update(freq_hz=np.arange(8.0) ** 2), "freq_hz"),
        (lambda a: a.update(noise_var=[1.0, 0.0]), "noise_var"),
    ],
)
def test_recording_errors_name_the_array(change, field):
    t, links, cfr, freq = small_cfr()
    args = dict(t=t, links=links, cfr=cfr, freq_hz=freq)
    change(args)
    t = args.pop("t")
    links = args.pop("links")
    with pytest.raises(sl.ScatterlocError) as e:
        sl.Recording(t, links, **args)
    assert isinstance(e.value, ValueError)
    assert e.value.field == field, str(e.value)
    assert str(e.value).startswith(field)


@pytest.mark.parametrize(
    "kw, field",
    [
        (dict(tap_spacing_s=1e-9), "tap0_s"),
        (dict(tap0_s=0.0), "tap_spacing_s"),
        (dict(tap0_s=0.0, tap_spacing_s=1e-9, freq_hz=np.arange(8.0)), "freq_hz"),
        (dict(tap0_s=0.0, tap_spacing_s=1e-9, pulse=[0.5, 1 + 0j, 0.5]), "pulse_spacing_s"),
        (dict(tap0_s=0.0, tap_spacing_s=-1e-9), "tap_spacing_s"),
    ],
)
def test_recording_cir_errors(kw, field):
    t, links, cir, _ = small_cfr()
    with pytest.raises(sl.ScatterlocError) as e:
        sl.Recording(t, links, cir=cir, **kw)
    assert e.value.field == field, str(e.value)


# --------------------------------------------------------------------------------------------
# .npz round trip


def test_write_read_roundtrip_sim(sim, tmp_path):
    for path in (tmp_path / "a.npz", str(tmp_path / "b.npz")):
        sl.write_recording(path, sim.rec)
        back = sl.read_recording(path)
        assert_same_bits(back.samples, sim.rec.samples)
        assert_same_bits(back.t, sim.rec.t)
        assert_same_bits(back.links, sim.rec.links)
        assert_same_bits(back.freq_hz, sim.rec.freq_hz)
        assert_same_bits(back.noise_var, sim.rec.noise_var)
        # numpy reads it with the documented keys and dtypes.
        with np.load(path) as z:
            assert sorted(z.files) == sorted(["t_s", "links", "cfr", "freq_hz", "noise_var"])
            assert_same_bits(z["t_s"], sim.rec.t)
            assert_same_bits(z["links"], sim.rec.links)
            assert_same_bits(z["cfr"], sim.rec.samples)
            assert_same_bits(z["freq_hz"], sim.rec.freq_hz)
            assert_same_bits(z["noise_var"], sim.rec.noise_var)
    assert (tmp_path / "a.npz").read_bytes() == (tmp_path / "b.npz").read_bytes()
    assert sorted(p.name for p in tmp_path.iterdir()) == ["a.npz", "b.npz"]  # no temporaries left


def test_write_read_roundtrip_cir_with_pulse(tmp_path):
    t, links, cir, _ = small_cfr(4)
    pulse = np.array([0.5, 2.0 + 0.5j, 0.5 - 0.25j])
    r = sl.Recording(
        t, links, cir=cir, tap0_s=-2e-9, tap_spacing_s=1e-9, pulse=pulse,
        pulse_spacing_s=0.5e-9, noise_var=[1e-3, 2e-3],
    )
    p = tmp_path / "c.npz"
    sl.write_recording(p, r)
    back = sl.read_recording(p)
    assert back.layout == "cir" and back.taps == (-2e-9, 1e-9)
    assert_same_bits(back.samples, cir)
    with np.load(p) as z:
        assert sorted(z.files) == sorted(
            ["t_s", "links", "cir", "tap0_s", "tap_spacing_s", "pulse", "pulse_spacing_s", "noise_var"]
        )
        assert_same_bits(z["cir"], cir)
        assert_same_bits(z["t_s"], t)
        assert z["links"].dtype == np.int64 and z["links"].tolist() == links.tolist()
        for k, v in (("tap0_s", -2e-9), ("tap_spacing_s", 1e-9), ("pulse_spacing_s", 0.5e-9)):
            assert z[k].dtype == np.float64 and z[k].shape == () and float(z[k]) == v
        # The pulse is normalised to p(0) = 1 (every sample divided by the middle one).
        assert z["pulse"].dtype == np.complex128
        np.testing.assert_allclose(z["pulse"], pulse / pulse[1], rtol=1e-15, atol=0)
        assert z["pulse"][1] == 1.0


def test_read_numpy_savez(tmp_path):
    """A file numpy writes (docs/recording.md) reads as the same recording built from arrays."""
    t, links, cfr, freq = small_cfr(5)
    nv = np.array([1e-2, 3e-2])
    np.savez(tmp_path / "n.npz", t_s=t, links=links, cfr=cfr, freq_hz=freq, noise_var=nv)
    np.savez_compressed(tmp_path / "z.npz", t_s=t, links=links, cfr=cfr, freq_hz=freq, noise_var=nv)
    for name in ("n.npz", "z.npz"):
        r = sl.read_recording(tmp_path / name)
        assert_same_bits(r.samples, cfr)
        assert_same_bits(r.t, t)
        assert_same_bits(r.freq_hz, freq)
        assert_same_bits(r.noise_var, nv)


# --------------------------------------------------------------------------------------------
# simulate_recording vs `cir simulate`


def test_simulate_equals_cli(sim):
    d = sim.cli.cwd / "sim"
    for rec, name in ((sim.rec, "recording.npz"), (sim.cal, "calibration.npz")):
        with np.load(d / name) as z:
            assert sorted(z.files) == sorted(["t_s", "links", "cfr", "freq_hz", "noise_var"])
            assert_same_bits(rec.samples, z["cfr"])
            assert_same_bits(rec.t, z["t_s"])
            assert_same_bits(rec.links, z["links"])
            assert_same_bits(rec.freq_hz, z["freq_hz"])
            assert_same_bits(rec.noise_var, z["noise_var"])
        back = sl.read_recording(d / name)
        assert_same_bits(back.samples, rec.samples)
    truth = json.loads((d / "truth.json").read_text())
    assert sim.truth == truth
    assert_bitwise(sim.truth, truth)
    # Shapes: 4 s at 50 ms (both ends) and 1 s of the empty area; 241 bins of B/N.
    assert sim.rec.samples.shape == (81, 4, 241)
    assert sim.cal.samples.shape == (21, 4, 241)
    np.testing.assert_allclose(sim.rec.t, 0.05 * np.arange(81), rtol=0, atol=1e-12)
    np.testing.assert_allclose(np.diff(sim.rec.freq_hz), sim.s.bandwidth_hz / 241, rtol=1e-9)
    # The truth's walk starts at the hangar's first waypoint at 1.4 m/s.
    assert truth["states"][0] == [2.0, 4.0, 1.4, 0.0]
    assert sim.rec.layout == sim.cal.layout == "cfr"
    # The truth's LoS path of each link is the Tx-Rx distance over c (closed form).
    tx, rx = sim.s.transmitters, sim.s.receivers
    for l, (i, j) in enumerate(sim.s.link_indices):
        los = [p for p in truth["paths"][0][l] if p["kind"] == "los"]
        assert len(los) == 1
        assert los[0]["delay_s"] == pytest.approx(np.linalg.norm(tx[i] - rx[j]) / C, rel=1e-12)


def test_simulate_scene_and_walk_equal_cli(tmp_path):
    cli = Cli(tmp_path)
    s = sl.Scenario.preset("sensors2019")
    cli.write("s.json", s.to_dict())
    cli.run(
        "cir", "simulate", "--scenario", "s.json", "--out-dir", "w", "--dt", "0.1",
        "--duration", "2", "--walk", "0,0 10,5 10,10", "--speed", "1.2",
        "--calibration-duration", "0.5", "--seed", "9",
    )
    scene = cli.file("w/scene.json")
    rec, cal, truth = sl.simulate_recording(
        s, walk=[[0, 0], [10, 5], [10, 10]], speed=1.2, duration=2.0, dt=0.1,
        calibration_duration=0.5, seed=9,
    )
    with np.load(tmp_path / "w" / "recording.npz") as z:
        assert_same_bits(rec.samples, z["cfr"])
    with np.load(tmp_path / "w" / "calibration.npz") as z:
        assert_same_bits(cal.samples, z["cfr"])
    assert_bitwise(truth, cli.file("w/truth.json"))
    assert truth["states"][0][:2] == [0.0, 0.0]
    # The scene the CLI used, given back as a dict, simulates the same recordings.
    rec2, cal2, truth2 = sl.simulate_recording(s, scene=scene, calibration_duration=0.5, seed=9)
    assert_same_bits(rec2.samples, rec.samples)
    assert_same_bits(cal2.samples, cal.samples)
    assert_bitwise(truth2, truth)


@pytest.mark.parametrize(
    "kw, field",
    [
        (dict(speed=-1.0), "speed_mps"),
        (dict(dt=0.0), "dt_s"),
        (dict(duration=-2.0), "duration_s"),
        (dict(walk=[[0.0, 0.0]]), "walk"),
        (dict(calibration_duration=-1.0), "calibration_duration_s"),
    ],
)
def test_simulate_errors_name_the_request_field(kw, field):
    s = sl.Scenario.preset("sensors2019")
    with pytest.raises(sl.ScatterlocError) as e:
        sl.simulate_recording(s, **kw)
    assert e.value.field == field, str(e.value)


# --------------------------------------------------------------------------------------------
# estimate_recording vs `cir estimate`


def test_estimate_recording_equals_cli(sim):
    # calibration=None: the recursive background, as the CLI without --calibration.
    assert_bitwise(sim.paths.to_dict(), sim.est)
    fe = sim.est["front_end"]
    assert fe["statics"] == "background" and fe["delay_reference"] == "absolute"
    assert [l["empty_snapshots"] for l in fe["links"]] == [0] * 4
    assert len(sim.est["alignment"]) == 81 and "calibration" in sim.est
    # With the empty area's recording, as --calibration.
    assert_bitwise(sim.paths_cal.to_dict(), sim.est_cal)
    fe = sim.est_cal["front_end"]
    assert [l["empty_snapshots"] for l in fe["links"]] == [21] * 4
    assert [l["background"] for l in fe["links"]] == [True] * 4
    assert sim.est_cal["calibration"]["snapshot_count"] == 21
    prog = sim.progress
    total = 81 * 4
    assert prog and prog[-1] == (total, total)
    assert all(t == total for _, t in prog) and [d for d, _ in prog] == sorted(d for d, _ in prog)
    if sim.seed != 1:
        return
    # The same from the file, and with one worker.
    q = sl.estimate_recording(sim.s, sl.read_recording(sim.cli.cwd / "sim" / "recording.npz"), threads=1)
    assert_bitwise(q.to_dict(), sim.est)


# (flags of `cir estimate`, keywords of `estimate_recording`; "CAL" = the empty area's recording)
FRONT_END_SETTINGS = [
    (("--max-paths", "4", "--pfa", "0.01"), dict(max_paths=4, pfa=0.01)),
    (("--statics", "clusters", "--calibration", "sim/calibration.npz"), dict(statics="clusters", calibration="CAL")),
    (("--statics", "background", "--calibration", "sim/calibration.npz"), dict(statics="background", calibration="CAL")),
    (("--delay-reference", "los", "--background-time", "2"), dict(delay_reference="los", background_time=2.0)),
    (("--delay-reference", "los", "--calibration", "sim/calibration.npz"), dict(delay_reference="los", calibration="CAL")),
    (("--delay-reference", "absolute"), dict(delay_reference="absolute")),
    (("--calibration-range", "0,0.5"), dict(calibration_range=(0.0, 0.5))),
]


def with_cal(sim, kw: dict) -> dict:
    return {k: (sim.cal if v == "CAL" else v) for k, v in kw.items()}


@pytest.mark.parametrize("flags, kw", FRONT_END_SETTINGS)
def test_estimate_recording_settings_equal_cli(sim, flags, kw):
    if sim.seed != 1 and "max_paths" not in kw:
        pytest.skip("one seed is enough for the other settings")
    out = "est" + "".join(c for c in "_".join(flags) if c.isalnum() or c == "_") + ".json"
    sim.cli.run("cir", "estimate", "--scenario", "s.json", "--cir", "sim/recording.npz", "--out", out, *flags)
    doc = sim.cli.file(out)
    p = sl.estimate_recording(sim.s, sim.rec, **with_cal(sim, kw))
    assert_bitwise(p.to_dict(), doc)
    fe = doc["front_end"]
    if "max_paths" in kw:
        assert doc["max_paths"] == 4 and doc["p_fa"] == 0.01
        assert max(len(es) for per in doc["estimates"] for es in per) <= 4
    assert fe["statics"] == kw.get("statics", "background")
    assert fe["delay_reference"] == kw.get("delay_reference", "absolute")
    assert fe["background_time_s"] == kw.get("background_time", 10.0)
    if "calibration_range" in kw:
        # 0 <= t <= 0.5 s: 11 snapshots of the walk are the empty area.
        assert [l["empty_snapshots"] for l in fe["links"]] == [11] * 4


def test_estimate_recording_unsynchronized_equals_cli(sim, tmp_path):
    """A recording whose `synchronized` is False reads delays relative to the direct path (C10)
    unless delay_reference says otherwise, in the package as in the CLI (the flag in the file)."""
    if sim.seed != 1:
        pytest.skip("one seed is enough")
    r = sim.rec
    un = sl.Recording(r.t, r.links, cfr=r.samples, freq_hz=r.freq_hz, noise_var=r.noise_var, synchronized=False)
    sl.write_recording(sim.cli.cwd / "unsync.npz", un)
    sim.cli.run("cir", "estimate", "--scenario", "s.json", "--cir", "unsync.npz", "--out", "est_unsync.json")
    doc = sim.cli.file("est_unsync.json")
    assert doc["front_end"]["delay_reference"] == "los"
    assert_bitwise(sl.estimate_recording(sim.s, un).to_dict(), doc)
    assert_bitwise(
        sl.estimate_recording(sim.s, un, delay_reference="absolute").to_dict(), sim.est
    )


def test_paths_arrays(sim):
    p = sim.paths
    rows = est_rows(sim.est)
    k = len(rows)
    assert len(p) == k > 0
    for name, dtype in (
        ("snapshot", np.int64), ("link", np.int64), ("delay", np.float64),
        ("amplitude", np.complex128), ("sigma", np.float64), ("snr_db", np.float64),
        ("track", np.int64), ("confirmed", np.bool_),
    ):
        a = getattr(p, name)
        assert a.dtype == dtype, name
        assert a.shape == (k,), name
    assert isinstance(p.snr_db, np.ma.MaskedArray)
    assert np.ma.getmaskarray(p.snr_db).shape == (k,)
    assert p.noise_var.dtype == np.float64 and p.noise_var.shape == (81, 4)
    assert p.t.dtype == np.float64 and p.t.shape == (81,)
    # Each array is EST.json in long format (snapshot-major, then link).
    assert p.snapshot.tolist() == [s for s, _, _ in rows]
    assert p.link.tolist() == [l for _, l, _ in rows]
    assert p.delay.tolist() == [e["delay_s"] for _, _, e in rows]
    assert p.sigma.tolist() == [e["sigma_s"] for _, _, e in rows]
    assert p.track.tolist() == [e["track"] for _, _, e in rows]
    assert p.confirmed.tolist() == [e["confirmed"] for _, _, e in rows]
    snr = [None if m else v for v, m in zip(p.snr_db.data.tolist(), np.ma.getmaskarray(p.snr_db).tolist())]
    assert snr == [e["snr_db"] for _, _, e in rows]
    amp = np.array([e["amplitude"] for _, _, e in rows])
    np.testing.assert_allclose(np.abs(p.amplitude), amp, rtol=1e-15, atol=0)
    assert p.noise_var.tolist() == sim.est["noise_var"]
    assert p.t.tolist() == sim.est["t_s"]
    # Delays are physical: within the recorded span of the 241-bin grid (1/Δf) and ≥ 0.
    assert (p.delay >= 0).all() and (p.delay < 241 / sim.s.bandwidth_hz).all()
    assert (p.sigma > 0).all()


def test_estimate_one_link_equals_est_json(sim):
    """`estimate` on one link's responses is `cir estimate --statics clusters` (every full
    response estimated, absolute delays) on that link."""
    rec = sim.rec
    sim.cli.run(
        "cir", "estimate", "--scenario", "s.json", "--cir", "sim/recording.npz", "--calibration",
        "sim/calibration.npz", "--statics", "clusters", "--out", "est_clusters.json",
    )
    est = sim.cli.file("est_clusters.json")
    for l in range(4):
        p = sl.estimate(rec.samples[:, l, :], freq_hz=rec.freq_hz, t=rec.t, noise_var=rec.noise_var[l])
        rows = est_rows(est, l)
        assert len(p) == len(rows) > 0
        assert p.link is None and p.to_dict() is None
        assert p.snapshot.tolist() == [s for s, _, _ in rows]
        assert_bitwise(p.delay.tolist(), [e["delay_s"] for _, _, e in rows])
        assert_bitwise(p.sigma.tolist(), [e["sigma_s"] for _, _, e in rows])
        assert p.track.tolist() == [e["track"] for _, _, e in rows]
        assert p.confirmed.tolist() == [e["confirmed"] for _, _, e in rows]
        # EST.json's |alpha| goes through the core's portable sqrt: equal to 1e-15.
        amp = np.array([e["amplitude"] for _, _, e in rows])
        np.testing.assert_allclose(np.abs(p.amplitude), amp, rtol=1e-15, atol=0)
        assert p.noise_var.shape == (81,)
        assert_same_bits(p.noise_var, np.array([e[l] for e in est["noise_var"]]))
        assert_same_bits(p.t, rec.t)


# --------------------------------------------------------------------------------------------
# estimate on synthetic responses: delays against the closed form of C1 / C2


def two_paths(seed: int, S: int = 12):
    """The two-path link of docs/recording.md (sensors2019's band) with noise of variance 1e-14 W."""
    rng = np.random.default_rng(seed)
    N, B = 241, 120e6
    freq = (np.arange(N) - (N - 1) / 2) * (B / N)
    tau = np.array([40e-9, 75e-9])
    alpha = np.array([1e-5, 4e-6j])
    nv = 1e-14
    h = (alpha[None, :] * np.exp(-2j * np.pi * freq[:, None] * tau[None, :])).sum(axis=1)
    noise = rng.normal(size=(S, N)) + 1j * rng.normal(size=(S, N))
    return freq, tau, alpha, nv, h[None, :] + math.sqrt(nv / 2) * noise


@pytest.mark.parametrize("seed", [1, 2, 3])
def test_estimate_cfr_finds_the_two_paths(seed):
    freq, tau, alpha, nv, cfr = two_paths(seed)
    p = sl.estimate(cfr, freq_hz=freq, noise_var=nv)
    assert p.t.tolist() == list(range(12))
    for s in range(12):
        k = p.snapshot == s
        strongest = np.argsort(-np.abs(p.amplitude[k]))[:2]
        d, a, sg = p.delay[k][strongest], p.amplitude[k][strongest], p.sigma[k][strongest]
        order = np.argsort(d)
        d, a, sg = d[order], a[order], sg[order]
        assert np.all(np.abs(d - tau) < 6 * sg), (s, d, sg)
        np.testing.assert_allclose(np.abs(a), np.abs(alpha), rtol=0.05)
        # C4: sigma of a path at SNR |alpha|^2 N / nv over a band of 241 bins is ~0.1 ps..ns
        assert np.all(sg < 1e-10)
    assert (p.noise_var == nv).all()


@pytest.mark.parametrize("seed", [1, 2, 3])
def test_estimate_cir_finds_the_two_paths(seed):
    """C2 with the ideal sinc of the band: h[m] = sum alpha sinc(B (t_m - tau))."""
    rng = np.random.default_rng(seed)
    B, M, S = 120e6, 64, 8
    dtap = 1 / (2 * B)
    tap0 = 0.0
    tm = tap0 + dtap * np.arange(M)
    tau = np.array([40e-9, 75e-9])
    alpha = np.array([1e-5, 4e-6j])
    nv = 1e-14
    h = (alpha[None, :] * np.sinc(B * (tm[:, None] - tau[None, :]))).sum(axis=1)
    cir = h[None, :] + math.sqrt(nv / 2) * (rng.normal(size=(S, M)) + 1j * rng.normal(size=(S, M)))
    p = sl.estimate(cir, tap0_s=tap0, tap_spacing_s=dtap, bandwidth_hz=B, noise_var=nv)
    for s in range(S):
        k = p.snapshot == s
        strongest = np.argsort(-np.abs(p.amplitude[k]))[:2]
        d, sg = p.delay[k][strongest], p.sigma[k][strongest]
        order = np.argsort(d)
        assert np.all(np.abs(d[order] - tau) < 6 * sg[order] + 1e-12), (s, d, sg)
    with pytest.raises(sl.ScatterlocError) as e:
        sl.estimate(cir, tap0_s=tap0, tap_spacing_s=dtap)
    assert e.value.field == "bandwidth_hz"


def test_estimate_errors():
    freq, _, _, _, cfr = two_paths(1, S=3)
    with pytest.raises(sl.ScatterlocError) as e:
        sl.estimate(cfr[None], freq_hz=freq)
    assert e.value.field == "response"
    with pytest.raises(sl.ScatterlocError) as e:
        sl.estimate(cfr, freq_hz=freq, t=[0.0, 1.0])
    assert e.value.field == "t"
    with pytest.raises(sl.ScatterlocError) as e:
        sl.estimate(cfr)
    assert e.value.field == "freq_hz"


# --------------------------------------------------------------------------------------------
# cir_track vs `cir track`


def track_cli(sim, out: str, *extra: str, calibration: bool = True) -> dict:
    cal = ("--calibration", "sim/calibration.npz") if calibration else ()
    sim.cli.run("cir", "track", "--scenario", "s.json", *cal, "--cir", "sim/recording.npz", "--out", out, *extra)
    return sim.cli.file(out)


def check_segments(t, doc: dict) -> None:
    """`segments` is TRACK.json's, in time order, disjoint; states (and covariances) exist at
    exactly the snapshots of a segment (masked between segments, C11)."""
    assert isinstance(t.segments, list)
    assert_bitwise(t.segments, doc["segments"])
    S = len(doc["t_s"])
    inside = np.zeros(S, dtype=bool)
    prev_last = -1
    for g in t.segments:
        assert set(g) >= {"first", "last", "t_first_s", "t_last_s", "end", "confirmed_at", "hits", "start"}
        assert prev_last < g["first"] <= g["confirmed_at"] <= g["last"] < S
        assert g["t_first_s"] == doc["t_s"][g["first"]] and g["t_last_s"] == doc["t_s"][g["last"]]
        assert g["start"]["snapshot"] == g["first"]
        assert g["end"] in ("innovation", "misses", "outside_area", "filter", "end")
        inside[g["first"] : g["last"] + 1] = True
        prev_last = g["last"]
    # Only the last segment can run to the recording's end.
    assert all(g["end"] != "end" for g in t.segments[:-1])
    has_state = [s is not None for s in doc["states"]]
    assert has_state == inside.tolist()
    assert (~np.ma.getmaskarray(t.states).any(axis=1) == inside).all()
    assert (np.ma.getmaskarray(t.states).all(axis=1) == ~inside).all()
    if t.segments:
        assert doc["start"] == t.segments[0]["start"]
    else:
        assert doc["start"] is None


def check_track_arrays(t, doc: dict) -> None:
    S = len(doc["t_s"])
    assert t.t.tolist() == doc["t_s"]
    assert isinstance(t.states, np.ma.MaskedArray) and t.states.shape == (S, 4)
    assert isinstance(t.covariances, np.ma.MaskedArray) and t.covariances.shape == (S, 4, 4)
    assert t.states.dtype == t.covariances.dtype == np.float64
    states = [None if m.all() else v for v, m in zip(t.states.data.tolist(), np.ma.getmaskarray(t.states))]
    assert states == doc["states"]
    covs = [
        None if m.all() else v
        for v, m in zip(t.covariances.data.tolist(), np.ma.getmaskarray(t.covariances))
    ]
    assert covs == doc["covariances"]
    assert t.links_used.dtype == np.int64 and t.links_used.tolist() == doc["links_used"]
    assert isinstance(t.delays_used, np.ma.MaskedArray) and t.delays_used.shape == (S, 4)
    used = [
        [None if m else v for v, m in zip(row, mrow)]
        for row, mrow in zip(t.delays_used.data.tolist(), np.ma.getmaskarray(t.delays_used).tolist())
    ]
    assert used == doc["delays_used_s"]
    # links_used counts the delays taken.
    assert (t.links_used == (~np.ma.getmaskarray(t.delays_used)).sum(axis=1)).all()
    check_segments(t, doc)


@pytest.mark.parametrize("with_truth", [True, False])
def test_cir_track_equals_cli(sim, with_truth):
    extra = ("--truth", "sim/truth.json") if with_truth else ()
    doc = track_cli(sim, "track.json", *extra)
    t = sl.cir_track(sim.s, sim.rec, sim.cal, truth=sim.truth if with_truth else None)
    assert_bitwise(t.to_dict(), doc)
    check_track_arrays(t, doc)
    if not with_truth:
        assert t.error is None and "error" not in doc
        return
    # The error is the distance to the truth's position (closed form), masked nowhere once
    # the track has started.
    truth = np.array(sim.truth["states"])
    st = t.states.filled(np.nan)
    expect = np.hypot(st[:, 0] - truth[:, 0], st[:, 1] - truth[:, 1])
    started = ~np.ma.getmaskarray(t.states).any(axis=1)
    assert isinstance(t.error, np.ma.MaskedArray) and t.error.shape == (81,)
    assert (np.ma.getmaskarray(t.error) == ~started).all()
    np.testing.assert_allclose(t.error.compressed(), expect[started], rtol=1e-12, atol=1e-12)
    stats = doc["error"]
    assert stats["count"] == int(started.sum())
    assert stats["max_m"] == pytest.approx(float(expect[started].max()), rel=1e-12)
    assert stats["median_m"] == pytest.approx(float(np.median(expect[started])), rel=1e-12)
    assert stats["rms_m"] == pytest.approx(float(np.sqrt(np.mean(expect[started] ** 2))), rel=1e-12)
    assert stats["fraction_below_1m"] == pytest.approx(float(np.mean(expect[started] < 1.0)), rel=1e-12)
    # The walker is tracked (docs/cli.md: a few dm on the hangar walk).
    assert stats["median_m"] < 1.0


@pytest.mark.parametrize("with_truth", [True, False])
def test_cir_track_without_calibration_equals_cli(sim, with_truth):
    """calibration=None: a recursive background of the walk itself, as the CLI without
    --calibration."""
    extra = ("--truth", "sim/truth.json") if with_truth else ()
    doc = track_cli(sim, "track_rec.json", *extra, calibration=False)
    t = sl.cir_track(sim.s, sim.rec, truth=sim.truth if with_truth else None)
    assert_bitwise(t.to_dict(), doc)
    check_track_arrays(t, doc)
    assert [l["empty_snapshots"] for l in doc["front_end"]["links"]] == [0] * 4
    if not with_truth:  # calibration given positionally as None
        assert_bitwise(sl.cir_track(sim.s, sim.rec, None).to_dict(), doc)


def test_cir_track_statics_clusters_equals_cli(sim):
    doc = track_cli(sim, "track_clusters.json", "--truth", "sim/truth.json", "--statics", "clusters")
    t = sl.cir_track(sim.s, sim.rec, sim.cal, truth=sim.truth, statics="clusters")
    assert_bitwise(t.to_dict(), doc)
    assert doc["front_end"]["statics"] == "clusters"
    check_track_arrays(t, doc)


def test_cir_track_front_end_settings_equal_cli(sim):
    if sim.seed != 1:
        pytest.skip("one seed is enough for the other settings")
    doc = track_cli(
        sim, "track_fe.json", "--delay-reference", "los", "--background-time", "3",
        "--calibration-range", "0,0.6", "--max-paths", "6", "--pfa", "0.005", calibration=False,
    )
    t = sl.cir_track(
        sim.s, sim.rec, delay_reference="los", background_time=3.0, calibration_range=[0.0, 0.6],
        max_paths=6, pfa=0.005,
    )
    assert_bitwise(t.to_dict(), doc)
    check_track_arrays(t, doc)


def test_cir_track_ukf_equals_cli(sim):
    doc = track_cli(sim, "track_ukf.json", "--truth", "sim/truth.json", "--filter", "ukf")
    t = sl.cir_track(sim.s, sim.rec, sim.cal, truth=sim.cli.cwd / "sim" / "truth.json", filter="ukf")
    assert_bitwise(t.to_dict(), doc)
    assert doc["filter"] == "ukf"
    check_track_arrays(t, doc)


def test_cir_track_from_files_equals_cli(sim):
    if sim.seed != 1:
        pytest.skip("one seed is enough for the file inputs and the other settings")
    doc = track_cli(sim, "track_b.json", "--sigma", "budget", "--association", "spec", "--process-noise", "0.5")
    d = sim.cli.cwd / "sim"
    t = sl.cir_track(
        str(d / "../s.json"), sl.read_recording(d / "recording.npz"),
        sl.read_recording(d / "calibration.npz"), sigma="budget", association="spec",
        process_noise=0.5,
    )
    assert_bitwise(t.to_dict(), doc)
    check_track_arrays(t, doc)
    # The tracker's settings as the CLI's flags: pf with its own, extent_sigma.
    doc = track_cli(
        sim, "track_pf.json", "--filter", "pf", "--particles", "300", "--seed", "4",
        "--extent-sigma-m", "0.3", "--process-noise", "2",
    )
    t = sl.cir_track(
        sim.s, sim.rec, calibration=sim.cal, filter="pf", particles=300, seed=4,
        extent_sigma=0.3, process_noise=2.0,
    )
    assert_bitwise(t.to_dict(), doc)
    assert doc["filter"] == "pf" and doc["extent_sigma_m"] == 0.3
    check_track_arrays(t, doc)


@pytest.mark.parametrize(
    "kw, field",
    [
        pytest.param(
            dict(filter="kf"), "filter",
        ),
        (dict(seed=3), "seed"),
        (dict(association="nearest"), "association"),
        (dict(sigma="fixed"), "sigma"),
        (dict(particles=100), "particles"),
        (dict(statics="x"), "statics"),
        (dict(delay_reference="relative"), "delay_reference"),
        (dict(background_time=-1.0), "background_time_s"),
        (dict(extent_sigma=-0.1), "extent_sigma_m"),
        (dict(process_noise=-1.0), "process_noise"),
        (dict(calibration_range=(0.0, 0.2)), "calibration_range_s"),
        (dict(max_paths=0), "max_paths"),
    ],
)
def test_cir_track_errors(kw, field):
    s = sl.Scenario.preset("sensors2019")
    rec = tiny_recording()
    with pytest.raises(sl.ScatterlocError) as e:
        sl.cir_track(s, rec, rec, **kw)
    assert e.value.field == field, str(e.value)
    assert str(e.value).startswith(field)


def tiny_recording():
    t, _, cfr, freq = small_cfr(S=5, P=2, N=8)
    return sl.Recording(t, np.array([[0, 0], [0, 1]]), cfr=cfr, freq_hz=freq)


@pytest.mark.parametrize(
    "kw, field",
    [
        (dict(statics="x"), "statics"),
        (dict(delay_reference="x"), "delay_reference"),
        (dict(background_time=0.0), "background_time_s"),
        (dict(calibration_range=(0.3, 0.1)), "calibration_range_s"),
        (dict(calibration_range=(5.0, 6.0)), "calibration_range_s"),
        # C7 alone needs the empty area (a calibration recording or a time range).
        (dict(statics="clusters"), "calibration"),
    ],
)
def test_estimate_recording_errors(kw, field):
    s = sl.Scenario.preset("sensors2019")
    rec = tiny_recording()
    for call in (sl.estimate_recording, sl.cir_track):
        with pytest.raises(sl.ScatterlocError) as e:
            call(s, rec, **kw)
        assert e.value.field == field, (call.__name__, str(e.value))
        assert str(e.value).startswith(field)
