"""PicoScenes files of Intel AX200/AX210 ("IWLMVM") CSI, written here byte by byte (RXS frames
of an `RxSBasic` v1 and a `CSI` v3 segment, the structs of csiread's `_picoscenes.pyx` and of
PicoScenes' `rxs_parsing_core`), read by `sl.read_csi` and by csiread 1.4.1 (issue 40).

The reference is PicoScenes' `CSI::fromIWLMVM`: the buffer is NumTx·NumRx·NumTones·4 bytes of
i16 (real, imaginary) pairs, the column-major {NumTones, NumTx, NumRx} matrix, on the subcarrier
table of the format and CBW (`TABLES`, copied from its `CSISegment.cxx`), shifted by
SubcarrierOffset. The firmware writes 0 at the pilot tones, which scatterloc leaves out (as its
FeitCSI reader does). csiread 1.4.1 reads these frames but not as PicoScenes does, and the
tests assert its differences rather than hide them: it drops, instead of the m-th pilot (0-based)
at table position p_m, the entry at p_m + m (each removal shifts the next); it orders chain
before stream (value i = k + K·(r + NumRx·t)); with two streams its later blocks shift too; and
it mis-reads HE 160 (and, on chain 2, HT 20 — not used here). Where it agrees — VHT 80 and HE 80
with one stream, every subcarrier both keep; the first block and the tones before the first
pilot with two — the values are compared exactly; HE 160 against the reference table only."""

from __future__ import annotations

import struct
from pathlib import Path

import csiread  # pinned in python/requirements-test.txt
import numpy as np

import scatterloc as sl

AX200, AX210 = 0x2000, 0x2100

# CSISegment.cxx's tables as ranges, and the pilots' positive indices (IEEE 802.11-2016
# §21.3.10.10 for VHT 80; 802.11ax §27.3.11.13 for HE 80, and HE 160: the HE 80 pilots
# around ±512).
TABLES = {
    (2, 80): ([(-122, -2), (2, 122)], [11, 39, 75, 103]),
    (3, 80): ([(-500, -3), (3, 500)], [24, 92, 158, 226, 266, 334, 400, 468]),
    (3, 160): (
        [(-1012, -515), (-509, -12), (12, 509), (515, 1012)],
        [44, 112, 178, 246, 286, 354, 420, 488, 536, 604, 670, 738, 778, 846, 912, 980],
    ),
}


def table(fmt: int, cbw: int) -> np.ndarray:
    return np.concatenate([np.arange(a, b + 1) for a, b in TABLES[(fmt, cbw)][0]])


def segment(name: str, version: int, body: bytes) -> bytes:
    n = name.encode() + b"\0"
    s = bytes([len(n)]) + n + struct.pack("<H", version) + body
    return struct.pack("<I", len(s)) + s


def rxs_basic(device: int, tstamp: int, fmt: int, cbw: int, n_tx: int, n_rx: int) -> bytes:
    # v1: deviceType, tstamp, centerFreq, packetFormat, cbw, GI, MCS, numSTS, numESS, numRx,
    # noiseFloor, rssi, rssi_ctl0..2.
    return struct.pack(
        "<HQhBHHBBBBbbbbb", device, tstamp, 5500, fmt, cbw, 800, 3, n_tx, 0, n_rx, -90, 40, 41, 42, 0
    )


def csi_v3(device: int, fmt: int, cbw: int, offset: int, values: np.ndarray) -> bytes:
    """values: (NumRx, NumTx, K) complex integers, written tone fastest, then stream, then chain."""
    n_rx, n_tx, k = values.shape
    pairs = np.stack([values.real, values.imag], axis=-1).astype("<i2")
    buf = pairs.tobytes()  # C order of (r, t, k, part): k + K·(t + NumTx·r)
    assert len(buf) == n_tx * n_rx * k * 4
    spacing = 78_125 if fmt == 3 else 312_500
    head = struct.pack(
        "<HbHQQIHBBBHBhI",
        device, fmt, cbw, 5_500_000_000, cbw * 1_000_000, spacing, k, n_tx, n_rx, 0, 1, 0, offset, len(buf),
    )
    return head + buf


def frame(segments: list[bytes]) -> bytes:
    body = struct.pack("<IHB", 0x20150315, 1, len(segments)) + b"".join(segments)
    return struct.pack("<I", len(body)) + body


def pattern(seed: int, shape: tuple[int, ...]) -> np.ndarray:
    rng = np.random.default_rng(seed)
    re = rng.integers(-32768, 32768, size=shape)
    im = rng.integers(-32768, 32768, size=shape)
    return re + 1j * im


def write(path: Path, device: int, fmt: int, cbw: int, n_tx: int, n_rx: int, offset: int) -> list[np.ndarray]:
    k = len(table(fmt, cbw))
    frames, out = [], []
    for f in range(3):
        v = pattern(100 * fmt + f, (n_rx, n_tx, k))
        out.append(v)
        rxs = segment("RxSBasic", 1, rxs_basic(device, 1_000_000 + 250 * f, fmt, cbw, n_tx, n_rx))
        frames.append(frame([rxs, segment("CSI", 3, csi_v3(device, fmt, cbw, offset, v))]))
    path.write_bytes(b"".join(frames))
    return out


def csiread_of(path: Path, k: int, n_rx: int, n_tx: int) -> csiread.Picoscenes:
    p = csiread.Picoscenes(str(path), {"CSI": [k, n_rx, n_tx]}, if_report=False)
    p.read()
    return p


def kept_by_csiread(fmt: int, cbw: int) -> np.ndarray:
    """csiread 1.4.1's drop: the m-th pilot's table position plus m."""
    t = table(fmt, cbw)
    half = TABLES[(fmt, cbw)][1]
    pos = np.flatnonzero(np.isin(np.abs(t), half))
    return np.delete(t, pos + np.arange(len(pos)))


def compare_with_csiread(path: Path, o: dict, fmt: int, cbw: int, n_tx: int, offset: int) -> None:
    """Every subcarrier csiread 1.4.1 and scatterloc both keep holds the same values."""
    k, half = len(table(fmt, cbw)), TABLES[(fmt, cbw)][1]
    p = csiread_of(path, k, 2, n_tx)
    info = p.raw["CSI"]["Info"]
    assert p.count == 3 and list(info["NumTones"]) == [k] * 3
    np.testing.assert_array_equal(p.raw["RxSBasic"]["Timestamp"], 1_000_000 + 250 * np.arange(3))
    n = k - 2 * len(half)
    idx = p.raw["CSI"]["SubcarrierIndex"][:, :n]
    np.testing.assert_array_equal(idx, np.tile(kept_by_csiread(fmt, cbw) + offset, (3, 1)))
    ours = {int(s): j for j, s in enumerate(o["subcarriers"])}
    a, b = np.array([(j, ours[int(s)]) for j, s in enumerate(idx[0]) if int(s) in ours]).T
    # Only csiread's first removal hits a pilot: it keeps the others and drops as many data tones.
    assert len(a) == n - (2 * len(half) - 1)
    ref = p.raw["CSI"]["CSI"][:, a, :, :]  # (frame, k, r', t')
    if n_tx == 1:
        np.testing.assert_array_equal(o["csi"][:, :, :, b], ref.transpose(0, 2, 3, 1))
    else:
        # Block 0 (chain 1, stream 1) is the same in every order.
        np.testing.assert_array_equal(o["csi"][:, 0, 0, b], ref[:, :, 0, 0])
        # csiread orders chain before stream: its [r', t'] is raw block r' + 2·t', ours [r, t]
        # block t + 2·r (PicoScenes' and FeitCSI's order) — the antenna axes swap. (Past the
        # first pilot its later blocks are shifted too: compared on the tones before it.)
        first = int(np.flatnonzero(np.isin(np.abs(table(fmt, cbw)), half))[0])
        pre = p.raw["CSI"]["CSI"][:, :first, :, :]
        np.testing.assert_array_equal(o["csi"][:, :, :, :first], pre.transpose(0, 3, 2, 1))
        assert not np.array_equal(o["csi"][:, :, :, :first], pre.transpose(0, 2, 3, 1))


def check_against_reference(o: dict, raw: list[np.ndarray], fmt: int, cbw: int, offset: int) -> None:
    t = table(fmt, cbw)
    pilot = np.isin(np.abs(t), TABLES[(fmt, cbw)][1])
    np.testing.assert_array_equal(o["subcarriers"], t[~pilot] + offset)
    # The pilots are not reported subcarriers, with or without an offset (the pilot list
    # shifts with the indices, so no shifted data tone is taken for a pilot).
    assert len(o["pilots"]) == 0
    np.testing.assert_array_equal(o["csi"], np.stack([v[:, :, ~pilot] for v in raw]))
    np.testing.assert_allclose(o["t_s"], (1_000_000 + 250 * np.arange(3)) * 1e-6)


def test_ax200_he160_against_the_reference_table(tmp_path: Path) -> None:
    # csiread 1.4.1 mis-reads HE 160 (it loses the whole block 12…509 and misplaces values on
    # chain 2): compared with PicoScenes' table and the values written only.
    path = tmp_path / "ax200_he160.csi"
    raw = write(path, AX200, 3, 160, 1, 2, 0)
    o = sl.read_csi(path)
    assert len(table(3, 160)) == 1992
    assert (o["format"], o["device"], o["frame_format"]) == ("picoscenes", "Intel AX200", "HE-SU")
    assert (o["n_rx"], o["n_tx"], o["spacing_hz"], o["center_hz"]) == (2, 1, 78_125.0, 5.5e9)
    assert o["csi"].shape == (3, 2, 1, 1992 - 32)
    check_against_reference(o, raw, 3, 160, 0)


def test_ax200_he80_one_stream_equals_csiread(tmp_path: Path) -> None:
    path = tmp_path / "ax200_he80.csi"
    raw = write(path, AX200, 3, 80, 1, 2, 0)
    o = sl.read_csi(path)
    assert o["csi"].shape == (3, 2, 1, 996 - 16) and o["bandwidth_hz"] == 80e6
    check_against_reference(o, raw, 3, 80, 0)
    compare_with_csiread(path, o, 3, 80, 1, 0)


def test_ax210_vht80_equals_csiread_one_and_two_streams(tmp_path: Path) -> None:
    for n_tx, offset in ((1, 0), (2, 4)):
        path = tmp_path / f"ax210_vht80_{n_tx}.csi"
        raw = write(path, AX210, 2, 80, n_tx, 2, offset)
        o = sl.read_csi(path)
        assert (o["device"], o["frame_format"], o["n_rx"], o["n_tx"]) == ("Intel AX210", "VHT", 2, n_tx)
        assert o["csi"].shape == (3, 2, n_tx, 242 - 8)
        check_against_reference(o, raw, 2, 80, offset)
        compare_with_csiread(path, o, 2, 80, n_tx, offset)


def test_mixed_devices_keep_the_first_frames_layout(tmp_path: Path) -> None:
    a, b = tmp_path / "a.csi", tmp_path / "b.csi"
    write(a, AX200, 3, 160, 1, 2, 0)
    write(b, AX210, 2, 80, 2, 2, 4)
    mixed = tmp_path / "mixed.csi"
    mixed.write_bytes(a.read_bytes() + b.read_bytes())
    o = sl.read_csi(mixed)
    assert o["csi"].shape == (3, 2, 1, 1960)
    assert [s[0] for s in o["skipped"]] == [3, 4, 5]
    assert o["skipped"][0][1].startswith("Intel AX210 VHT 80 MHz")
