"""The six real Wi-Fi CSI files of tests/data/csi (CSIKit's, MIT) read by scatterloc's own readers
(`sl.read_csi`, the library's `csi` edge) against independent readers that parse the same files:
csiread 1.4.1 (Intel 5300, PicoScenes, Nexmon) and CSIKit 2.5 (FeitCSI, ESP32). Values are
compared exactly (the formats hold integers, or — Nexmon's packed floats — values csiread
decodes with the same arithmetic); then `scatterloc cir convert` writes the documented `.npz`
layout, which numpy reads back onto the masked grid, equal to `sl.read_recording` on the CSI
file directly (issue 40)."""

from __future__ import annotations

import json
from pathlib import Path
from typing import Any

import csiread  # pinned in python/requirements-test.txt
import numpy as np
import pytest

import scatterloc as sl
from conftest import ROOT, Cli

DATA = ROOT / "tests" / "data" / "csi"



def ours(name: str) -> dict[str, Any]:
    return sl.read_csi(DATA / name)


def test_intel5300_equals_csiread() -> None:
    d = csiread.Intel(str(DATA / "intel/example.dat"), nrxnum=3, ntxnum=2, if_report=False)
    d.read()
    o = ours("intel/example.dat")
    assert o["format"] == "intel5300" and (o["n_rx"], o["n_tx"]) == (3, 2)
    ref = np.asarray(d.csi)  # (frames, 30, rx, tx)
    assert o["csi"].shape == (26, 3, 2, 30)
    np.testing.assert_array_equal(o["csi"], ref.transpose(0, 2, 3, 1))
    # csiread's subcarrier indices of the 20 MHz grouping (its `scidx`).
    np.testing.assert_array_equal(o["subcarriers"], csiread.utils.scidx(20, 2))
    # Times: timestamp_low in µs, relative to nothing (the card's clock).
    np.testing.assert_allclose(o["t_s"], np.asarray(d.timestamp_low, dtype=np.float64) * 1e-6)


def test_picoscenes_equals_csiread() -> None:
    size = {
        "CSI": [30, 3, 2],
        "PilotCSI": [0, 0, 0],
        "LegacyCSI": [0, 0, 0],
        "BasebandSignals": [0, 0, 0],
        "PreEQSymbols": [0, 0, 0],
        "MPDU": 1522,
    }
    p = csiread.Picoscenes(str(DATA / "pico/picoscenes_iwl5300_example.csi"), size, if_report=False)
    p.read()
    info = p.raw["CSI"]["Info"]
    o = ours("pico/picoscenes_iwl5300_example.csi")
    # csiread pads every frame to 3 × 2; the file holds 99 frames of 2 Rx × 1 Tx and 13 of 2 × 2,
    # which scatterloc skips (a recording has one antenna configuration), naming them.
    keep = (info["NumRx"] == 2) & (info["NumTx"] == 1)
    assert int(keep.sum()) == o["csi"].shape[0] == 99
    assert len(o["skipped"]) == 112 - 99
    ref = p.raw["CSI"]["CSI"][keep][:, :, :2, :1]  # (frames, 30, rx, tx)
    np.testing.assert_array_equal(o["csi"], ref.transpose(0, 2, 3, 1))
    np.testing.assert_array_equal(o["subcarriers"], p.raw["CSI"]["SubcarrierIndex"][0])
    assert o["center_hz"] == float(info["CarrierFreq"][0])


def test_nexmon_equals_csiread() -> None:
    n = csiread.Nexmon(str(DATA / "nexmon/example_4366c0.pcap"), chip="4366c0", bw=80, if_report=False)
    n.read()
    o = ours("nexmon/example_4366c0.pcap")
    ref = np.asarray(n.csi)  # (293, 256), FFT order: bin k at k mod 256
    k = o["subcarriers"]
    assert o["csi"].shape == (293, 1, 1, 242)
    np.testing.assert_array_equal(o["csi"][:, 0, 0, :], ref[:, k % 256])
    np.testing.assert_allclose(o["t_s"], n.sec + n.usec * 1e-6, rtol=0, atol=1e-6)


def csikit(name: str, **kw: Any) -> Any:
    from CSIKit import reader

    f = str(DATA / name)
    return reader.get_reader(f).read_file(f, scaled=False, **kw)


@pytest.mark.parametrize("name", ["feitcsi/VHT80_5500.csi", "feitcsi/HESU160_5500.csi"])
def test_feitcsi_equals_csikit(name: str) -> None:
    # interpolate=False: CSIKit's default fills the pilot tones by interpolation.
    d = csikit(name, interpolate=False)
    o = ours(name)
    frames = [np.asarray(f.csi_matrix) for f in d.frames]  # (K_all, rx, tx) each
    assert o["csi"].shape[0] == len(frames)
    k_all = frames[0].shape[0]
    # CSIKit gives every tone of the 802.11 map (pilots included, where the firmware writes 0);
    # scatterloc leaves the pilots out: compare at the tones it keeps.
    full = full_map(k_all)
    at = np.searchsorted(full, o["subcarriers"])
    np.testing.assert_array_equal(full[at], o["subcarriers"])
    for i, m in enumerate(frames):
        np.testing.assert_array_equal(o["csi"][i], m[at].transpose(1, 2, 0))
        # The tones left out are the firmware's zeros.
        rest = np.setdiff1d(np.arange(k_all), at)
        assert np.all(m[rest] == 0)


def full_map(k: int) -> np.ndarray:
    """The 802.11 tone maps of FeitCSI's two files: VHT80 (242) and HE160 (1992)."""
    if k == 242:
        return np.r_[-122:-1, 2:123]
    if k == 1992:
        return np.r_[-1012:-514, -509:-11, 12:510, 515:1013]
    raise AssertionError(k)


def test_esp32_equals_csikit() -> None:
    d = csikit("esp32/example_data.csv")
    o = ours("esp32/example_data.csv")
    assert o["csi"].shape[0] == len(d.frames) == 60
    for i, f in enumerate(d.frames):
        m = np.asarray(f.csi_matrix)[:, 0]  # 64 values: CSIKit takes the first int8 as real
        # Espressif's buffer: (imaginary, real) int8 pairs, L-LTF in the order 0…31, −32…−1.
        # CSIKit reads (real, imaginary): ours = CSIKit's with the parts swapped.
        swapped = m.imag + 1j * m.real
        np.testing.assert_array_equal(o["csi"][i, 0, 0], swapped[o["subcarriers"] % 64])


ALL = [
    "intel/example.dat",
    "pico/picoscenes_iwl5300_example.csi",
    "nexmon/example_4366c0.pcap",
    "feitcsi/VHT80_5500.csi",
    "feitcsi/HESU160_5500.csi",
    "esp32/example_data.csv",
]


@pytest.mark.parametrize("name", ALL)
def test_convert_writes_the_masked_grid(cli: Cli, name: str) -> None:
    out = cli.json("cir", "convert", str(DATA / name), "rec.npz")
    raw = ours(name)
    z = np.load(cli.cwd / "rec.npz")
    # The occupied subcarriers (all reported ones but Nexmon's: its 20 MHz frames fill one
    # sub-channel of the 80 MHz chanspec).
    power = (np.abs(raw["csi"]) ** 2).mean(axis=(0, 1, 2))
    kept = raw["subcarriers"][power > 0] if name.startswith("nexmon") else raw["subcarriers"]
    f = z["freq_hz"]
    mask = z["system_response"]
    k_grid = np.round(f / raw["spacing_hz"]).astype(np.int64)
    assert out["grid_bins"] == len(f) == k_grid[-1] - k_grid[0] + 1
    np.testing.assert_allclose(f, k_grid * raw["spacing_hz"], rtol=1e-15)
    present = k_grid[mask != 0]
    assert set(present.tolist()) <= set(kept.tolist())
    assert len(present) == len(raw["subcarriers"]) - out["unoccupied"]["count"]
    if not name.startswith("nexmon"):
        np.testing.assert_array_equal(present, raw["subcarriers"])
    assert int(z["synchronized"]) == 0
    cfr = z["cfr"]
    assert np.all(cfr[:, :, mask == 0] == 0)
    # The same recording as Python opens from the CSI file directly.
    rec = sl.read_recording(DATA / name)
    np.testing.assert_array_equal(rec.samples, cfr)
    assert out["frames"] == cfr.shape[0] and out["format"] == raw["format"]
