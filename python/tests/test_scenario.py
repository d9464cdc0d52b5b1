"""`scatterloc.Scenario`: constructors, conversions, validated edits and the measurement model at
points, against the CLI's `preset` output, closed forms and finite differences."""

from __future__ import annotations

import copy
import json
import math
import pickle
from pathlib import Path

import numpy as np
import pytest

import scatterloc as sl

C = 299_792_458.0


def test_preset_equals_cli(cli):
    for name in sl.Scenario.presets():
        s = sl.Scenario.preset(name)
        assert s.to_dict() == cli.json("preset", name)
        assert s.name == name


def test_every_constructor_gives_the_same_scenario(tmp_path: Path):
    s = sl.Scenario.preset("sensors2019")
    path = tmp_path / "s.json"
    s.save(path)
    text = path.read_text()
    variants = [
        sl.Scenario("sensors2019"),
        sl.Scenario(s.to_dict()),
        sl.Scenario(text),
        sl.Scenario(str(path)),
        sl.Scenario(path),
        sl.Scenario.from_dict(json.loads(text)),
        sl.Scenario.from_json(text),
        sl.Scenario.from_json("\ufeff" + text),
        sl.Scenario.from_file(path),
        s.copy(),
        copy.deepcopy(s),
        pickle.loads(pickle.dumps(s)),
    ]
    for v in variants:
        assert v == s
        assert v.to_json() == s.to_json()


def test_properties():
    s = sl.Scenario.preset("sensors2019")
    d = s.to_dict()
    assert s.transmitters.shape == (1, 2) and s.transmitters.dtype == np.float64
    assert s.receivers.shape == (4, 2)
    assert s.receivers.tolist() == [r["position_m"] for r in d["receivers"]]
    assert s.links == [("Tx", f"Rx{i}") for i in range(1, 5)]
    assert s.link_indices.tolist() == [[0, i] for i in range(4)]
    assert s.link_indices.dtype == np.int64
    assert s.link_count == 4
    assert s.area == (d["area_m"]["x"][0], d["area_m"]["x"][1], d["area_m"]["y"][0], d["area_m"]["y"][1])
    assert s.bandwidth_hz == d["radio"]["bandwidth_hz"]
    assert s.carrier_hz == d["radio"]["carrier_hz"]
    assert s.rcs_m2 == d["target"]["rcs_m2"]


def test_bad_input_names_the_field(tmp_path: Path):
    d = sl.Scenario.preset("sensors2019").to_dict()
    d["radio"]["carrier_hz"] = 1e15
    with pytest.raises(sl.ScatterlocError) as e:
        sl.Scenario(d)
    assert e.value.field == "radio.carrier_hz"
    assert e.value.kind == "OutOfRange"
    assert isinstance(e.value, ValueError)
    d = sl.Scenario.preset("sensors2019").to_dict()
    d["receivers"][1]["name"] = "Rx1"
    with pytest.raises(sl.ScatterlocError, match="Rx1") as e:
        sl.Scenario(d)
    assert e.value.kind == "DuplicateName"
    with pytest.raises(sl.ScatterlocError) as e:
        sl.Scenario.from_json('{"name": "x"}')
    assert e.value.kind == "Parse"
    with pytest.raises(sl.ScatterlocError) as e:
        sl.Scenario.preset("nope")
    assert e.value.kind == "UnknownPreset"
    with pytest.raises(FileNotFoundError):
        sl.Scenario.from_file(tmp_path / "missing.json")
    with pytest.raises(sl.ScatterlocError) as e:
        sl.Scenario(3.5)  # type: ignore[arg-type]
    assert e.value.field == "source"
    with pytest.raises(sl.ScatterlocError):
        sl.Scenario({"radio": float("nan")})


def test_edits_are_validated_and_atomic():
    s = sl.Scenario.preset("sensors2019")
    before = s.to_json()
    with pytest.raises(sl.ScatterlocError) as e:
        s.move_receiver(2, [1e9, 0.0])
    assert e.value.field == "position[0]"
    with pytest.raises(sl.ScatterlocError) as e:
        s.move_receiver(9, [1.0, 0.0])
    assert e.value.kind == "IndexOutOfRange"
    with pytest.raises(sl.ScatterlocError):
        s.set_bandwidth_hz(-1.0)
    with pytest.raises(sl.ScatterlocError):
        s.remove_transmitter(0)  # the last one
    with pytest.raises(sl.ScatterlocError) as e:
        s.set_tx_pattern(0, "yagi")  # type: ignore[arg-type]
    assert e.value.kind == "UnknownPattern"
    with pytest.raises(sl.ScatterlocError):
        s.set_area(10.0, 0.0, 0.0, 10.0)
    assert s.to_json() == before

    s.move_receiver(0, (1.5, 2.5))
    assert s.receivers[0].tolist() == [1.5, 2.5]
    i = s.add_receiver([3.0, 4.0])
    assert i == 4 and s.link_count == 5
    s.remove_receiver(i)
    assert s.link_count == 4
    j = s.add_transmitter([0.0, 5.0])
    assert s.link_count == 8
    s.remove_transmitter(j)
    s.set_bandwidth_hz(2e8)
    assert s.bandwidth_hz == 2e8
    s.set_rcs_m2(10.0)
    s.set_tx_power_dbm(0, 30.0)
    s.set_tx_gain_dbi(0, 5.0)
    s.set_rx_gain_dbi(1, 3.0)
    s.set_noise_figure_db(7.0)
    s.set_carrier_hz(2.4e9)
    s.set_tx_pattern(0, "omni")
    s.set_name("edited")
    d = s.to_dict()
    assert d["radio"]["bandwidth_hz"] == 2e8 and d["target"]["rcs_m2"] == 10.0
    assert d["transmitters"][0]["pattern"] == {"kind": "omni"}
    assert d["name"] == "edited"
    # The edited scenario is a valid scenario file.
    assert sl.Scenario(d) == s


def test_delays_closed_form():
    s = sl.Scenario.preset("sensors2019")
    rng = np.random.default_rng(3)
    pts = rng.uniform([-7, -9], [29, 25], size=(5, 7, 2))
    d = s.delays(pts)
    assert d.shape == (5, 7, 4) and d.dtype == np.float64
    tx = s.transmitters[s.link_indices[:, 0]]
    rx = s.receivers[s.link_indices[:, 1]]
    ref = (
        np.linalg.norm(pts[..., None, :] - tx, axis=-1) + np.linalg.norm(pts[..., None, :] - rx, axis=-1)
    ) / C
    np.testing.assert_allclose(d, ref, rtol=1e-15)
    assert s.delays([4.0, 1.0]).shape == (4,)


def test_jacobian_finite_differences():
    s = sl.Scenario.preset("sensors2019")
    rng = np.random.default_rng(4)
    for p in rng.uniform([-7, -9], [29, 25], size=(20, 2)):
        j = s.delay_jacobian(p)
        assert j.shape == (4, 2)
        h = 1e-4
        fd = np.stack(
            [(s.delays(p + [h, 0]) - s.delays(p - [h, 0])) / (2 * h), (s.delays(p + [0, h]) - s.delays(p - [0, h])) / (2 * h)],
            axis=1,
        )
        np.testing.assert_allclose(j, fd, rtol=1e-6, atol=1e-18)


def test_link_budget_matches_crlb_document(cli):
    s = sl.Scenario.preset("sensors2019")
    cli.write("s.json", s.to_dict())
    doc = cli.json("crlb", "--scenario", "s.json", "--at", "10,0")
    snr = s.snr_db([10.0, 0.0])
    sig = s.sigma_delays([10.0, 0.0])
    for k, link in enumerate(doc["links"]):
        assert snr[k] == link["snr_db"]
        assert sig[k] == link["sigma_delay_s"]
    # E8: sigma = 1/sqrt(8 pi^2 beta^2 SNR), beta^2 = B^2/12.
    beta2 = s.bandwidth_hz**2 / 12
    np.testing.assert_allclose(sig, 1 / np.sqrt(8 * math.pi**2 * beta2 * 10 ** (snr / 10)), rtol=1e-12)


def test_points_are_checked():
    s = sl.Scenario.preset("sensors2019")
    with pytest.raises(sl.ScatterlocError) as e:
        s.delays([[0.0, 0.0], [float("nan"), 1.0]])
    assert e.value.field == "points[1][0]" and e.value.kind == "NonFinite"
    with pytest.raises(sl.ScatterlocError) as e:
        s.delays([[0.0, 0.0, 1.0]])
    assert e.value.field == "points"
    with pytest.raises(sl.ScatterlocError):
        s.delays("abc")


def test_any_memory_order_reads_the_same_values():
    """C order, Fortran order, strided views and other dtypes give the same numbers."""
    s = sl.Scenario.preset("sensors2019")
    rng = np.random.default_rng(5)
    pts = rng.uniform(-5, 20, size=(6, 2))
    ref = s.delays(pts)
    for variant in (np.asfortranarray(pts), pts.T.copy().T, np.repeat(pts, 2, axis=0)[::2],
                    pts.tolist()):
        assert s.delays(variant).tobytes() == ref.tobytes()
    ints = np.array([[1, 2], [3, -4]])
    assert s.delays(ints).tobytes() == s.delays(ints.astype(np.float64)).tobytes()
    big = np.asfortranarray(rng.uniform(-5, 20, size=(3, 4, 2)))
    assert s.delays(big).tobytes() == s.delays(np.ascontiguousarray(big)).tobytes()
