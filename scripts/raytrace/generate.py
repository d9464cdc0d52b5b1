#!/usr/bin/env python3
"""Ray-traced test corpus: a person walking through an open area and a room, traced with Sionna RT.

What
----
Builds two 3-D scenes from primitive meshes written here (PLY boxes and cylinders), moves a
walker's body (a vertical cylinder, r = 0.2 m, h = 1.8 m, body-like material with diffuse
scattering) along a walk, traces every snapshot with NVIDIA Sionna RT (line of sight, specular
and diffuse reflection, max depth 3, 10^6 rays from the transmitter, no refraction or
diffraction) and writes per scene, under ``tests/data/raytraced/<scene>/``:

- ``scenario.json``  the scatterloc scenario (schema v1);
- ``walk.npz``       the walk, noise-free CFR recordings (docs/recording.md): t_s, links, cfr
                     complex64 [S, 4, 241], freq_hz;
- ``empty.npz``      the same area without the body, 20 snapshots, noise-free;
- ``walk-noisy.npz`` (``open`` only) the walk plus CN(0, sigma_p^2) noise at the link budget, with
                     ``noise_var``;
- ``truth.json``     the walker's states, the per-link noise variance, the generator's settings
                     and, per snapshot and link, the traced echo of the body and the LoS.

With ``--cpi [N,T]`` it traces instead only coherent-processing-interval bursts of the ``open``
walk (issue 42): at each scan start t_k of ``--cpi-scans``, N snapshots at t_k + n T (default
16 at 2.048 ms), the body moved to the walk's position at each instant, and writes
``open/walk-cpi.npz`` (the re-traced bursts), ``open/walk-cpi-doppler.npz`` (Sionna's own time
evolution: each scan's first trace with every path turned by its Doppler phase
e^{j 2 pi f_D n T}), ``open/walk-cpi-paths.npz`` (every body path: delay, coefficient, depth,
Doppler) and ``open/truth-cpi.json`` (states, geometric and traced range rates); see run_cpi.

Signal model (spec channel-estimation.md C1/C3). Sionna's ``Paths.a`` is the passband path
coefficient of isotropic, vertically polarised single-element antennas (|a|^2 = path gain) and
``Paths.tau`` the absolute delay; the baseband coefficient (what ``Paths.cir`` returns) is
a e^{-j 2 pi f_c tau}. This script computes that phase itself in float64, applies the
scenario's link budget per path,

    alpha_i = a_i e^{-j 2 pi f_c tau_i} sqrt(P_tx G_tx(phi_t,i) G_rx)       [sqrt(W)]

with G_tx the scenario transmitter's pattern at the path's azimuth of departure phi_t (the
sensors2019 parabolic pattern of src/measure/pattern.rs, reimplemented in numpy below:
G(psi)[dBi] = G0 - min(12 (psi/psi_3dB)^2, A_m), psi the azimuth off boresight; omni in the
room), and forms the CFR on the recording's bins f_n = (n - (N-1)/2) B/N, N = 241, B = 120 MHz:

    H[n] = sum_i alpha_i e^{-j 2 pi f_n tau_i}      (float64, stored as complex64)

The noise variance per link is sigma_p^2 = N k_B 290 K B F (F = 10 dB), so a path's integrated SNR
is |alpha|^2 / (k_B T0 B F) (C3).

Two choices beyond the plain trace: paths with a specular reflection on the body are left out
(a flat facet of the faceted cylinder reflects like an infinite mirror: see trace_snapshot), and
each link's paths are sorted to a canonical order before summing (the deterministic solver gives
the same set of paths every run, not always in the same order).

Versions (pinned; the numbers in tests/data/raytraced/README.md were made with these)
---------------------------------------------------------------------------------------
sionna-rt 2.2.0 (Apache-2.0), mitsuba 3.9.1, drjit 1.5.0 (variant llvm_ad_mono_polarized, CPU),
numpy 2.x, Debian libLLVM 19 (DRJIT_LIBLLVM_PATH must point at it: LLVM 15 aborts on the first
trace). ``PathSolver(deterministic=True)`` with a fixed seed: a re-run writes identical arrays.

How to run
----------
    scripts/raytrace/run.sh                       # installs what is missing, then runs this
    # or, with the venv already there:
    DRJIT_LIBLLVM_PATH=/usr/lib/x86_64-linux-gnu/libLLVM-19.so \\
        .tools/sionna/bin/python scripts/raytrace/generate.py [--scenes open,room] [--out DIR]
    .tools/sionna/bin/python scripts/raytrace/generate.py --report   # statistics of written files
    scripts/raytrace/run.sh --cpi                 # only the CPI bursts of open (~5 minutes)
    scripts/raytrace/run.sh --cpi --report        # only the CPI checks, from the written files

Run time (measured 2026-12-06 on this project's 2-core CPU machine, no GPU): 11-14 minutes for
both scenes (678 s and 838 s in two runs): open 189-220 s (201 snapshots, ~1 s each), room
459-649 s (147 snapshots, 3-4.4 s each: ~115 000 paths per link to sum), each after ~6-10 s of
set-up and JIT. A second run wrote byte-identical files.
CI never runs this: the corpus is committed.
"""

from __future__ import annotations

import argparse
import hashlib
import json
import math
import os
import shutil
import sys
import tempfile
import time

import numpy as np

LLVM19 = "/usr/lib/x86_64-linux-gnu/libLLVM-19.so"
if "DRJIT_LIBLLVM_PATH" not in os.environ and os.path.exists(LLVM19):
    os.environ["DRJIT_LIBLLVM_PATH"] = LLVM19

REPO = os.path.abspath(os.path.join(os.path.dirname(__file__), "..", ".."))
DEFAULT_OUT = os.path.join(REPO, "tests", "data", "raytraced")

# --- radio and recording -------------------------------------------------------------------------
C = 299_792_458.0              # speed of light, m/s (scipy.constants.speed_of_light, as Sionna)
K_B = 1.380649e-23             # Boltzmann, J/K (src/math/scalar.rs)
T0 = 290.0                     # reference temperature, K
CARRIER_HZ = 5.2e9
BANDWIDTH_HZ = 1.2e8
NOISE_FIGURE_DB = 10.0
N_BINS = 241
DF = BANDWIDTH_HZ / N_BINS
FREQ_HZ = (np.arange(N_BINS) - (N_BINS - 1) / 2) * DF
DT = 0.1                       # snapshot spacing, s
N_EMPTY = 20                   # snapshots of the empty-area recording
NODE_Z = 1.0                   # antenna height of every node, m

# --- tracer settings -----------------------------------------------------------------------------
MAX_DEPTH = 3
SAMPLES_PER_SRC = 1_000_000
MAX_PATHS_PER_SRC = 1_000_000
SEED = 7
NOISE_SEED = 1                 # numpy default_rng seed of walk-noisy.npz

# --- walker's body -------------------------------------------------------------------------------
BODY_RADIUS = 0.2
BODY_HEIGHT = 1.8
BODY_SEGMENTS = 48             # facets of the cylinder's side

# Materials. ITU-R P.2040 types come from Sionna's ITU table (valid 1-100 GHz for these);
# "body" is a homogeneous tissue-like slab: at 5.2 GHz the Gabriel et al. (1996) Cole-Cole fits
# (IT'IS tissue database) give eps_r ~ 36, sigma ~ 3.1 S/m for dry skin and eps_r ~ 49,
# sigma ~ 4.4 S/m for muscle; we take 45 and 3.5 S/m. Scattering coefficient S (Sionna's
# Lambertian model: a fraction S^2 of the reflected energy is scattered diffusely) 0.5 for the
# body (clothes, limbs, a shape far from a smooth cylinder; its specular paths are left out, see
# trace_snapshot), 0.2 for concrete and wood, 0.1 for metal.
MATERIALS = {
    "concrete": dict(itu_type="concrete", thickness=0.2, scattering_coefficient=0.2),
    "ground": dict(itu_type="concrete", thickness=0.3, scattering_coefficient=0.2),
    "metal": dict(itu_type="metal", thickness=0.01, scattering_coefficient=0.1),
    "wood": dict(itu_type="wood", thickness=0.05, scattering_coefficient=0.2),
    # upholstery (foam and fabric over a wooden frame): a low-loss dielectric, our rough guess
    "sofa": dict(relative_permittivity=2.5, conductivity=0.05, thickness=0.8,
                 scattering_coefficient=0.3),
    "body": dict(relative_permittivity=45.0, conductivity=3.5, thickness=0.4,
                 scattering_coefficient=0.5),
}


# =================================================================================================
# Scenes
# =================================================================================================

def sensors2019_scenario():
    """The sensors2019 preset (src/scenario/presets.rs), as `scatterloc preset sensors2019` prints it."""
    rx = [[-5.0, 12.0], [10.0, 10.0], [-6.0, -8.0], [12.0, -6.0]]
    return {
        "name": "sensors2019",
        "radio": {"carrier_hz": CARRIER_HZ, "bandwidth_hz": BANDWIDTH_HZ,
                  "noise_figure_db": NOISE_FIGURE_DB},
        "transmitters": [{"name": "Tx", "position_m": [0.0, 0.0], "power_dbm": 37.0,
                          "gain_dbi": 9.0,
                          "pattern": {"kind": "parabolic", "boresight_deg": 10.0,
                                      "beamwidth_deg": 70.0, "floor_db": 20.0}}],
        "receivers": [{"name": f"Rx{i + 1}", "position_m": p, "gain_dbi": 8.0}
                      for i, p in enumerate(rx)],
        "links": "all",
        "target": {"rcs_m2": 1.0},
        "area_m": {"x": [-7.5, 30.0], "y": [-10.0, 26.0]},
    }


def room_scenario():
    rx = [[9.5, 0.5], [9.5, 7.5], [5.0, 7.5], [5.0, 0.5]]
    return {
        "name": "raytraced-room",
        "radio": {"carrier_hz": CARRIER_HZ, "bandwidth_hz": BANDWIDTH_HZ,
                  "noise_figure_db": NOISE_FIGURE_DB},
        # 30 dBm, a channel sounder's 1 W ([S] transmits 37 dBm): at Wi-Fi's 20 dBm a person's
        # echo in this room is 8-19 dB (median per link), at or below the estimator's detection
        # threshold on two links; the tests' "10 dB lower" case covers that budget.
        "transmitters": [{"name": "Tx", "position_m": [0.5, 4.0], "power_dbm": 30.0,
                          "gain_dbi": 2.0, "pattern": {"kind": "omni"}}],
        "receivers": [{"name": f"Rx{i + 1}", "position_m": p, "gain_dbi": 2.0}
                      for i, p in enumerate(rx)],
        "links": "all",
        "target": {"rcs_m2": 1.0},
        "area_m": {"x": [0.0, 10.0], "y": [0.0, 8.0]},
    }


def box(x0, x1, y0, y1, z0, z1, skip=()):
    """Axis-aligned box as (vertices, triangles), outward counter-clockwise faces; `skip` names
    faces left out ("z0" for a box standing on the ground: its base is never seen)."""
    v = np.array([[x, y, z] for z in (z0, z1) for y in (y0, y1) for x in (x0, x1)], float)
    # vertex index = 4*iz + 2*iy + ix
    quads = {
        "z0": (0, 2, 3, 1), "z1": (4, 5, 7, 6),
        "y0": (0, 1, 5, 4), "y1": (2, 6, 7, 3),
        "x0": (0, 4, 6, 2), "x1": (1, 3, 7, 5),
    }
    tris = []
    for name, (a, b, c, d) in quads.items():
        if name not in skip:
            tris += [(a, b, c), (a, c, d)]
    return v, np.array(tris, int)


def cylinder(cx, cy, r, z0, z1, n, top=True, bottom=False):
    """Vertical n-gon prism (vertices on the circle of radius r), outward faces; n divisible by 4
    so that the bounding box is centred on the axis."""
    ang = 2 * np.pi * np.arange(n) / n
    ring = np.stack([cx + r * np.cos(ang), cy + r * np.sin(ang)], 1)
    v = np.concatenate([np.c_[ring, np.full(n, z0)], np.c_[ring, np.full(n, z1)],
                        [[cx, cy, z0], [cx, cy, z1]]])
    tris = []
    for k in range(n):
        k1 = (k + 1) % n
        tris += [(k, k1, n + k1), (k, n + k1, n + k)]
        if top:
            tris.append((2 * n + 1, n + k, n + k1))
        if bottom:
            tris.append((2 * n, k1, k))
    return v, np.array(tris, int)


def write_ply(path, mesh):
    v, f = mesh
    with open(path, "w") as fh:
        fh.write(f"ply\nformat ascii 1.0\nelement vertex {len(v)}\n"
                 "property float x\nproperty float y\nproperty float z\n"
                 f"element face {len(f)}\nproperty list uchar int vertex_indices\nend_header\n")
        for p in v:
            fh.write(f"{p[0]:.6f} {p[1]:.6f} {p[2]:.6f}\n")
        for t in f:
            fh.write(f"3 {t[0]} {t[1]} {t[2]}\n")


def open_scene():
    objects = [
        # ground: one large plane (two triangles) at z = 0, well past the scenario's area
        ("ground", (np.array([[-30, -25, 0], [50, -25, 0], [50, 40, 0], [-30, 40, 0]], float),
                    np.array([(0, 1, 2), (0, 2, 3)])), "ground"),
        # metal wall from (0, 14) to (10, 14), 0.2 m thick, 3 m high
        ("wall", box(0.0, 10.0, 13.9, 14.1, 0.0, 3.0, skip=("z0",)), "metal"),
        ("pole1", cylinder(15.0, 4.0, 0.15, 0.0, 4.0, 24), "metal"),
        ("pole2", cylinder(8.0, -3.0, 0.15, 0.0, 4.0, 24), "metal"),
    ]
    walk = dict(speed=1.4, waypoints=[(4, 2), (12, 2), (12, 8), (6, 6), (6, 1)],
                stop_at=2, stop_s=2.0)
    geometry = {
        "ground": "concrete plane z = 0, x in [-30, 50], y in [-25, 40]",
        "wall": "metal box x in [0, 10], y in [13.9, 14.1], z in [0, 3]",
        "pole1": "metal cylinder r 0.15 m at (15, 4), h 4 m (24 facets)",
        "pole2": "metal cylinder r 0.15 m at (8, -3), h 4 m (24 facets)",
    }
    return dict(name="open", scenario=sensors2019_scenario(), objects=objects, walk=walk,
                geometry=geometry)


def room_scene():
    t = 0.2  # wall, floor and ceiling thickness
    H = 3.0
    objects = [
        ("floor", box(-t, 10 + t, -t, 8 + t, -t, 0.0), "concrete"),
        ("ceiling", box(-t, 10 + t, -t, 8 + t, H, H + t), "concrete"),
        ("wall_w", box(-t, 0.0, -t, 8 + t, 0.0, H, skip=("z0", "z1")), "concrete"),
        ("wall_e", box(10.0, 10 + t, -t, 8 + t, 0.0, H, skip=("z0", "z1")), "concrete"),
        ("wall_s", box(0.0, 10.0, -t, 0.0, 0.0, H, skip=("z0", "z1", "x0", "x1")), "concrete"),
        ("wall_n", box(0.0, 10.0, 8.0, 8 + t, 0.0, H, skip=("z0", "z1", "x0", "x1")), "concrete"),
        ("table", box(7.8, 9.4, 3.6, 4.4, 0.0, 0.75, skip=("z0",)), "wood"),
        ("cabinet", box(1.0, 2.0, 7.5, 8.0, 0.0, 2.0, skip=("z0",)), "metal"),
        ("sofa", box(0.0, 0.9, 0.4, 2.4, 0.0, 0.8, skip=("z0",)), "sofa"),
    ]
    walk = dict(speed=1.2, waypoints=[(2, 2), (7, 2), (7, 6), (3, 5), (3, 3)],
                stop_at=2, stop_s=2.0)
    geometry = {
        "floor": "concrete box z in [-0.2, 0] under the room and its walls",
        "ceiling": "concrete box z in [3, 3.2]",
        "walls": "concrete, 0.2 m thick, 3 m high, inner faces x = 0, x = 10, y = 0, y = 8",
        "table": "wood box x in [7.8, 9.4], y in [3.6, 4.4], z in [0, 0.75]",
        "cabinet": "metal box x in [1, 2], y in [7.5, 8], z in [0, 2]",
        "sofa": "upholstery box x in [0, 0.9], y in [0.4, 2.4], z in [0, 0.8]",
    }
    return dict(name="room", scenario=room_scenario(), objects=objects, walk=walk,
                geometry=geometry)


SCENES = {"open": open_scene, "room": room_scene}


# =================================================================================================
# Walk
# =================================================================================================

def walk_legs(speed, waypoints, stop_at, stop_s):
    """The walk's legs [(t_start, t_end, p_start, velocity)] and its duration: piecewise-linear at
    `speed` through `waypoints`, standing still `stop_s` seconds at waypoints[stop_at]."""
    legs = []  # (t_start, t_end, p_start, velocity)
    t = 0.0
    for i in range(len(waypoints) - 1):
        p0, p1 = np.array(waypoints[i], float), np.array(waypoints[i + 1], float)
        if i == stop_at:
            legs.append((t, t + stop_s, p0, np.zeros(2)))
            t += stop_s
        d = float(np.linalg.norm(p1 - p0))
        legs.append((t, t + d / speed, p0, (p1 - p0) / d * speed))
        t += d / speed
    return legs, t


def walk_state_at(legs, tk):
    """[x, y, vx, vy] at time tk: the position on the leg containing tk in [start, end) (the last
    leg past the end) and that leg's velocity (0 during the stop)."""
    leg = next((lg for lg in legs if lg[0] <= tk < lg[1]), legs[-1])
    p = leg[2] + leg[3] * (tk - leg[0])
    return [p[0], p[1], leg[3][0], leg[3][1]]


def walk_states(speed, waypoints, stop_at, stop_s, dt=DT):
    """Piecewise-linear walk at `speed` through `waypoints`, standing still `stop_s` seconds at
    waypoints[stop_at]. Snapshots at t = k dt from 0 to the end (inclusive when it falls on the
    grid). Velocity: that of the leg containing t in [start, end); 0 during the stop; the last
    leg's at the final point."""
    legs, total = walk_legs(speed, waypoints, stop_at, stop_s)
    n = int(math.floor(total / dt + 1e-9)) + 1
    t_s = np.arange(n) / round(1 / dt)
    states = [walk_state_at(legs, tk) for tk in t_s]
    return t_s, np.array(states), total


# =================================================================================================
# Link budget
# =================================================================================================

def tx_gain_linear(tx, azimuth_rad):
    """Transmit gain toward azimuth(s), linear: src/measure/pattern.rs (spec 9.3) reimplemented,
    G(psi)[dBi] = G0 - min(12 (psi/psi_3dB)^2, A_m), psi the angle off boresight in the plane."""
    g0 = 10 ** (tx["gain_dbi"] / 10)
    pat = tx.get("pattern", {"kind": "omni"})
    az = np.asarray(azimuth_rad, float)
    if pat["kind"] == "omni":
        return np.full(az.shape, g0)
    psi = np.abs(np.angle(np.exp(1j * (az - np.deg2rad(pat["boresight_deg"])))))
    att_db = np.minimum(12 * (psi / np.deg2rad(pat["beamwidth_deg"])) ** 2, pat["floor_db"])
    return g0 * 10 ** (-att_db / 10)


def noise_power_w(scn):
    r = scn["radio"]
    return K_B * T0 * r["bandwidth_hz"] * 10 ** (r["noise_figure_db"] / 10)


# =================================================================================================
# Tracing
# =================================================================================================

class Tracer:
    """One Sionna scene (static objects, nodes, optional body) and a deterministic path solver."""

    def __init__(self, spec, mesh_dir, samples_per_src, max_depth):
        import mitsuba as mi
        import sionna.rt as rt
        self.mi, self.rt = mi, rt
        self.spec = spec
        self.samples, self.max_depth = samples_per_src, max_depth
        scn = spec["scenario"]
        scene = rt.load_scene()                      # empty scene
        scene.frequency = CARRIER_HZ
        scene.bandwidth = BANDWIDTH_HZ
        iso = dict(num_rows=1, num_cols=1, pattern="iso", polarization="V")
        scene.tx_array = rt.PlanarArray(**iso)
        scene.rx_array = rt.PlanarArray(**iso)
        self.materials = {}
        for name, kw in MATERIALS.items():
            kw = dict(kw)
            if "itu_type" in kw:
                self.materials[name] = rt.ITURadioMaterial(name=f"material_{name}", **kw)
            else:
                self.materials[name] = rt.RadioMaterial(name=f"material_{name}", **kw)
        objs = []
        for name, mesh, mat in spec["objects"]:
            path = os.path.join(mesh_dir, f"{spec['name']}-{name}.ply")
            write_ply(path, mesh)
            objs.append(rt.SceneObject(fname=path, name=name,
                                       radio_material=self.materials[mat]))
        scene.add(objs)
        for k, tx in enumerate(scn["transmitters"]):
            scene.add(rt.Transmitter(name=f"tx{k}",
                                     position=mi.Point3f(*tx["position_m"], NODE_Z)))
        for l, rx in enumerate(scn["receivers"]):
            scene.add(rt.Receiver(name=f"rx{l}", position=mi.Point3f(*rx["position_m"], NODE_Z)))
        self.scene = scene
        self.body = None
        self.body_ply = os.path.join(mesh_dir, f"{spec['name']}-body.ply")
        write_ply(self.body_ply, cylinder(0.0, 0.0, BODY_RADIUS, 0.0, BODY_HEIGHT, BODY_SEGMENTS,
                                          top=True, bottom=False))
        self.solver = rt.PathSolver(deterministic=True)

    def add_body(self):
        rt = self.rt
        self.body = rt.SceneObject(fname=self.body_ply, name="body",
                                   radio_material=self.materials["body"])
        self.scene.add(self.body)
        self.body_id = int(self.body.object_id)

    def move_body(self, x, y, vx=None, vy=None):
        # SceneObject.position is the centre of the bounding box: the base on the ground is z = 0
        self.body.position = self.mi.Point3f(float(x), float(y), BODY_HEIGHT / 2)
        if vx is not None:
            # only the paths' Doppler shifts (Paths.doppler) depend on it, not a or tau
            self.body.velocity = self.mi.Vector3f(float(vx), float(vy), 0.0)

    def trace(self, doppler=False):
        """Traces the current geometry; returns per receiver (link (0, l)) a dict of numpy arrays
        over the valid paths: a (complex128 passband coefficient), tau, phi_t, kind flags, and
        with `doppler` Sionna's Doppler shift of each path (Hz, from the objects' velocities)."""
        rt = self.rt
        paths = self.solver(self.scene, max_depth=self.max_depth,
                            max_num_paths_per_src=MAX_PATHS_PER_SRC,
                            samples_per_src=self.samples, synthetic_array=True,
                            los=True, specular_reflection=True, diffuse_reflection=True,
                            refraction=False, diffraction=False, seed=SEED)
        a_re, a_im = (np.asarray(x.numpy(), np.float64) for x in paths.a)
        a = (a_re + 1j * a_im)[:, 0, :, 0, :]                       # [rx, tx, P]
        tau = np.asarray(paths.tau.numpy(), np.float64)            # [rx, tx, P]
        phi_t = np.asarray(paths.phi_t.numpy(), np.float64)
        valid = np.asarray(paths.valid.numpy(), bool)
        if valid.ndim == 5:
            valid = valid[:, 0, :, 0, :]
        inter = np.asarray(paths.interactions.numpy())             # [depth, rx, tx, P]
        fd = np.asarray(paths.doppler.numpy(), np.float64) if doppler else None
        objs = np.asarray(paths.objects.numpy())
        out = []
        for l in range(a.shape[0]):
            m = valid[l, 0]
            it = inter[:, l, 0, m]
            ob = objs[:, l, 0, m]
            hit = it != rt.constants.InteractionType.NONE
            on_body = hit & (ob == self.body_id) if self.body is not None \
                else np.zeros(it.shape, bool)
            spec = it == rt.constants.InteractionType.SPECULAR
            # The solver returns the same set of paths on every run, but not always in the same
            # order (parallel compaction): sort to a canonical order, so that the float sums
            # below, and so the files, are bit-identical run to run.
            o = np.lexsort((phi_t[l, 0, m], a[l, 0, m].imag, a[l, 0, m].real, tau[l, 0, m]))
            it, ob, on_body, spec, hit = it[:, o], ob[:, o], on_body[:, o], spec[:, o], hit[:, o]
            m = np.flatnonzero(m)[o]
            out.append(dict(a=a[l, 0, m], tau=tau[l, 0, m], phi_t=phi_t[l, 0, m],
                            los=~hit.any(0),
                            diffuse=(it == rt.constants.InteractionType.DIFFUSE).any(0),
                            body=on_body.any(0), body_specular=(on_body & spec).any(0),
                            depth=hit.sum(0)))
            if fd is not None:
                out[-1]["doppler"] = fd[l, 0, m]
        return out


def link_cfr(p, tx, g_rx):
    """alpha and H[n] of one link from traced paths p (float64)."""
    scale = np.sqrt(10 ** ((tx["power_dbm"] - 30) / 10) * tx_gain_linear(tx, p["phi_t"]) * g_rx)
    alpha = p["a"] * np.exp(-2j * np.pi * CARRIER_HZ * p["tau"]) * scale
    h = np.zeros(N_BINS, np.complex128)
    for s in range(0, len(alpha), 8192):                     # chunks bound the memory
        tau = p["tau"][s:s + 8192]
        # e^{-j2pi f_n tau} by recurrence over n: e^{-j2pi f_0 tau} (e^{-j2pi df tau})^n, a
        # running product of unit phasors (error ~1e-14 after 241 steps, 10x faster than exp)
        ph = np.empty((len(tau), N_BINS), np.complex128)
        ph[:, 0] = np.exp(-2j * np.pi * FREQ_HZ[0] * tau)
        ph[:, 1:] = np.exp(-2j * np.pi * DF * tau)[:, None]
        np.cumprod(ph, axis=1, out=ph)
        h += alpha[s:s + 8192] @ ph
    return alpha, h


def trace_snapshot(tracer, scn, body_paths=False):
    """Traces the current geometry: CFR [links, N] and per-link facts about the paths.

    Paths with a specular reflection on the body are left out (counted in `dropped`): a facet
    of the faceted cylinder reflects like an infinite flat mirror in the image method, 15-20 dB
    above the glint of a curved body and only when a facet happens to line up, so they came
    and went between snapshots as 30-40 dB spikes. The body contributes its diffuse field.

    With `body_paths`, each link's dict also holds the kept body-touching paths: `body_tau`,
    `body_alpha` (the coefficients that enter H, sqrt(W)), `body_depth`, `body_doppler` (Hz), and
    all kept paths (`kept`, with their Doppler shifts)."""
    tx = scn["transmitters"][0]
    res = tracer.trace(doppler=body_paths)
    cfr = np.zeros((len(res), N_BINS), np.complex128)
    info = []
    for l, p0 in enumerate(res):
        keep = ~p0["body_specular"]
        p = {k: v[keep] for k, v in p0.items()}
        g_rx = 10 ** (scn["receivers"][l]["gain_dbi"] / 10)
        alpha, cfr[l] = link_cfr(p, tx, g_rx)
        pw = np.abs(alpha) ** 2
        los = np.flatnonzero(p["los"])
        d = dict(paths=int(len(alpha)), diffuse=int(p["diffuse"].sum()),
                 body_paths=int(p["body"].sum()), dropped=int((~keep).sum()),
                 los_m=float(p["tau"][los[0]] * C) if len(los) else None,
                 los_power_w=float(pw[los[0]]) if len(los) else None,
                 echo_m=None, echo_power_w=None, echo_depth=None,
                 direct_echo_m=None, direct_echo_power_w=None)
        if p["body"].any():
            b = np.flatnonzero(p["body"])
            i = b[np.argmax(pw[b])]
            d.update(echo_m=float(p["tau"][i] * C), echo_power_w=float(pw[i]),
                     echo_depth=int(p["depth"][i]))
        direct = p["body"] & (p["depth"] == 1)
        if direct.any():
            b = np.flatnonzero(direct)
            i = b[np.argmax(pw[b])]
            # in-band power of the single-bounce body paths: (1/N) sum_n |H_direct[n]|^2, what a
            # matched filter sees of the echo (its paths spread < 0.4 m, far below c/B = 2.5 m)
            _, h_direct = link_cfr({k: v[direct] for k, v in p.items()}, tx, g_rx)
            d.update(direct_echo_m=float(p["tau"][i] * C),
                     direct_echo_power_w=float(np.mean(np.abs(h_direct) ** 2)))
        if body_paths:
            b = p["body"]
            d.update(body_tau=p["tau"][b], body_alpha=alpha[b], body_depth=p["depth"][b],
                     body_doppler=p["doppler"][b], kept=p)
        info.append(d)
    return cfr, info


# =================================================================================================
# Output
# =================================================================================================

def links_array(scn):
    return np.array([[0, l] for l in range(len(scn["receivers"]))], np.int64)


def save_npz(path, t_s, scn, cfr, noise_var=None, extra=None):
    arrays = dict(t_s=np.asarray(t_s, np.float64), links=links_array(scn),
                  cfr=np.ascontiguousarray(cfr.astype(np.complex64)),
                  freq_hz=FREQ_HZ.astype(np.float64))
    if noise_var is not None:
        arrays["noise_var"] = np.asarray(noise_var, np.float64)
    if extra:
        arrays.update(extra)
    np.savez_compressed(path, **arrays)


def dump_json(path, obj):
    """JSON with one top-level field per line and one row per line for lists of lists."""
    def enc(v):
        return json.dumps(v, separators=(", ", ": "))
    lines = []
    for k, v in obj.items():
        if isinstance(v, list) and v and isinstance(v[0], list):
            inner = ",\n    ".join(enc(r) for r in v)
            lines.append(f'  "{k}": [\n    {inner}\n  ]')
        elif isinstance(v, dict):
            inner = ",\n    ".join(f"{json.dumps(kk)}: {enc(vv)}" for kk, vv in v.items())
            lines.append(f'  "{k}": {{\n    {inner}\n  }}')
        else:
            lines.append(f'  "{k}": {enc(v)}')
    with open(path, "w") as fh:
        fh.write("{\n" + ",\n".join(lines) + "\n}\n")


def r6(x):
    return None if x is None else round(float(x), 6)


def generator_info(tracer, spec):
    import mitsuba as mi
    import drjit as dr
    import sionna.rt as rt
    return {
        "tool": "scripts/raytrace/generate.py",
        "sionna_rt": rt.__version__, "mitsuba": mi.__version__, "drjit": dr.__version__,
        "variant": mi.variant(),
        "solver": "PathSolver(deterministic=True)",
        "max_depth": tracer.max_depth, "los": True, "specular": True, "diffuse": True,
        "refraction": False, "diffraction": False,
        "samples_per_src": tracer.samples, "max_num_paths_per_src": MAX_PATHS_PER_SRC,
        "seed": SEED, "antennas": "single isotropic element, vertical polarisation (iso, V)",
        "tx_gain": "scenario pattern at each path's azimuth of departure",
        "node_height_m": NODE_Z,
        "body_specular": "paths with a specular reflection on the body are left out "
                         "(flat-facet mirror artefact); the body scatters diffusely",
        "body": {"shape": f"vertical cylinder, {BODY_SEGMENTS} facets, open base",
                 "radius_m": BODY_RADIUS, "height_m": BODY_HEIGHT,
                 "centre_z_m": BODY_HEIGHT / 2, "material": "body"},
        "materials": MATERIALS,
        "objects": spec["geometry"],
        "walk": spec["walk"],
        "noisy_seed": NOISE_SEED,
    }


def run_scene(name, out_root, mesh_dir, samples, max_depth, limit=None):
    spec = SCENES[name]()
    scn = spec["scenario"]
    out = os.path.join(out_root, name)
    os.makedirs(out, exist_ok=True)
    t_start = time.time()
    tracer = Tracer(spec, mesh_dir, samples, max_depth)
    t_s, states, total = walk_states(**spec["walk"])
    if limit:
        t_s, states = t_s[:limit], states[:limit]
    print(f"[{name}] walk {total:.2f} s, {len(t_s)} snapshots", flush=True)

    # the empty area: static, so one trace repeated (a deterministic solver gives the same
    # arrays for every snapshot)
    empty_cfr, empty_info = trace_snapshot(tracer, scn)
    again, _ = trace_snapshot(tracer, scn)
    if not np.array_equal(again, empty_cfr):
        raise SystemExit(f"[{name}] two traces of the same scene differ: not deterministic")
    print(f"[{name}] empty: paths per link {[d['paths'] for d in empty_info]} "
          f"({time.time() - t_start:.1f} s)", flush=True)

    tracer.add_body()
    cfr = np.zeros((len(t_s), len(scn["receivers"]), N_BINS), np.complex128)
    info = []
    for k, st in enumerate(states):
        tracer.move_body(st[0], st[1])
        cfr[k], inf = trace_snapshot(tracer, scn)
        info.append(inf)
        if k % 20 == 0 or k == len(states) - 1:
            el = time.time() - t_start
            print(f"[{name}] {k + 1}/{len(states)} t={t_s[k]:.1f} s ({el:.0f} s elapsed) "
                  f"paths {[d['paths'] for d in inf]} echo "
                  f"{[None if d['echo_m'] is None else round(d['echo_m'], 2) for d in inf]}",
                  flush=True)
    elapsed = time.time() - t_start

    pn = noise_power_w(scn)
    noise_var = [N_BINS * pn] * len(scn["receivers"])
    save_npz(os.path.join(out, "walk.npz"), t_s, scn, cfr)
    save_npz(os.path.join(out, "empty.npz"), np.arange(N_EMPTY) / round(1 / DT), scn,
             np.repeat(empty_cfr[None], N_EMPTY, 0))
    if name == "open":
        rng = np.random.default_rng(NOISE_SEED)
        shape = cfr.shape
        w = rng.standard_normal(shape) + 1j * rng.standard_normal(shape)
        noisy = cfr.astype(np.complex64).astype(np.complex128) \
            + np.sqrt(np.asarray(noise_var) / 2)[None, :, None] * w
        save_npz(os.path.join(out, "walk-noisy.npz"), t_s, scn, noisy, noise_var)
    with open(os.path.join(out, "scenario.json"), "w") as fh:
        fh.write(json.dumps(scn, indent=2) + "\n")

    tx = np.array(scn["transmitters"][0]["position_m"])
    rxs = [np.array(r["position_m"]) for r in scn["receivers"]]
    centre = [[round(float(np.linalg.norm(st[:2] - tx) + np.linalg.norm(st[:2] - r)), 6)
               for r in rxs] for st in states]
    truth = {
        "t_s": [round(float(t), 9) for t in t_s],
        "states": [[round(float(v), 9) for v in st] for st in states],
        "noise_var_w": noise_var,
        "generator": generator_info(tracer, spec),
        "echo": [[r6(d["echo_m"]) for d in inf] for inf in info],
        "centre_range_m": centre,
        "echo_power_w": [[d["echo_power_w"] for d in inf] for inf in info],
        "echo_depth": [[d["echo_depth"] for d in inf] for inf in info],
        "direct_echo_m": [[r6(d["direct_echo_m"]) for d in inf] for inf in info],
        "direct_echo_power_w": [[d["direct_echo_power_w"] for d in inf] for inf in info],
        "los_m": [[r6(d["los_m"]) for d in inf] for inf in info],
        "los_power_w": [[d["los_power_w"] for d in inf] for inf in info],
        "paths": [[d["paths"] for d in inf] for inf in info],
        "diffuse_paths": [[d["diffuse"] for d in inf] for inf in info],
        "body_paths": [[d["body_paths"] for d in inf] for inf in info],
        "body_specular_dropped": [[d["dropped"] for d in inf] for inf in info],
        "empty": {"los_m": [r6(d["los_m"]) for d in empty_info],
                  "los_power_w": [d["los_power_w"] for d in empty_info],
                  "paths": [d["paths"] for d in empty_info],
                  "diffuse_paths": [d["diffuse"] for d in empty_info]},
    }
    dump_json(os.path.join(out, "truth.json"), truth)
    digest = hashlib.sha256(cfr.astype(np.complex64).tobytes()).hexdigest()[:16]
    print(f"[{name}] done in {elapsed:.1f} s; walk cfr sha256 {digest}", flush=True)
    return elapsed


# =================================================================================================
# CPI bursts (issue 42): N snapshots T apart at K scan times of the `open` walk
# =================================================================================================

CPI_SNAPSHOTS = 16             # N, snapshots per coherent processing interval
CPI_SPACING_S = 2.048e-3       # T: max unambiguous |range rate| lambda / (2 T) = 14.1 m/s
# scan start times (s): first leg (x 4 -> 12 at y = 2), second leg (y 2 -> 8 at x = 12), the stop
# at b (10-12 s: zero Doppler), the third leg (b -> c); every CPI lies inside one leg
CPI_SCANS = (0.5, 2.0, 3.5, 5.0, 6.5, 8.0, 9.5, 11.0, 13.0, 15.0)
CPI_OUT = "walk-cpi"
# |geometric - Sionna Doppler| bound of the check: 1/17 of the CPI's range-rate resolution
# lambda / (N T) = 1.76 m/s. The echo comes off the body's surface (up to 0.2 m sideways and
# 0.9 m up or down from the centre), which turns the unit vectors by a few degrees.
CPI_TOL_MPS = 0.1
# bound for the range rate estimated from walk-cpi-doppler.npz itself (walk - empty, matched to
# the direct echo's delay, pulse-pair): 1/7 of the resolution; the CFR also holds the body's
# multi-bounce paths (via the ground: another Doppler) and the shadowed static paths
CPI_CFR_TOL_MPS = 0.25


def cpi_names(out_name):
    """(recording, per-path file, truth file, Doppler-synthesised recording) names for
    --cpi-out NAME."""
    stem = out_name[len("walk"):] if out_name.startswith("walk") else "-" + out_name
    return (f"{out_name}.npz", f"{out_name}-paths.npz", f"truth{stem}.json",
            f"{out_name}-doppler.npz")


def geometric_range_rate(txp, rxp, state):
    """Bistatic range rate d(|p - tx| + |p - rx|)/dt of the body's centre p = (x, y, 0.9 m) moving
    at (vx, vy, 0), nodes at (x, y, 1.0 m): v . (u_tx + u_rx), u the 3-D unit vectors from the
    nodes to p."""
    p = np.array([state[0], state[1], BODY_HEIGHT / 2])
    v = np.array([state[2], state[3], 0.0])
    u_t = (p - txp) / np.linalg.norm(p - txp)
    u_r = (p - rxp) / np.linalg.norm(p - rxp)
    return float(v @ (u_t + u_r))


def cpi_traced_rates(n_cpi, spacing, snap, link, tau, alpha, depth, doppler, n_links, n_snap):
    """Per scan and link, from the traced single-bounce (Tx -> body -> Rx) paths, in m/s:

    - `fd`:  c (tau_{N-1} - tau_0) / ((N - 1) T), tau_n the delay of the strongest single-bounce
             body path of snapshot n: the finite difference across the CPI;
    - `fd_step`: the median over the N - 1 steps of c (tau_{n+1} - tau_n) / T (skips most of the
             steps where the strongest path changes from one Monte Carlo sample to another);
    - `centroid`: least-squares slope over the CPI of c times the power-weighted mean delay of
             those paths (snapshots without one left out);
    - `doppler`: -lambda times the power-weighted mean of Sionna's Doppler shift (Paths.doppler,
             from the body's velocity) over those paths in the N snapshots;
    - `phase`: -lambda / (2 pi T) arg sum_n z_{n+1} conj(z_n), z_n = sum of their alpha (the
             carrier-phased coefficients that enter H): the Doppler of the direct echo as the
             re-traced recording holds it (pulse-pair estimate).
    Each [K][links], None where a scan has too few such paths."""
    lam = C / CARRIER_HZ
    k_scans = n_snap // n_cpi
    keys = ("fd", "fd_step", "centroid", "doppler", "phase")
    out = {k: [[None] * n_links for _ in range(k_scans)] for k in keys}
    direct = depth == 1
    for l in range(n_links):
        strongest = np.full(n_snap, np.nan)
        centroid = np.full(n_snap, np.nan)
        z = np.zeros(n_snap, np.complex128)
        for s in range(n_snap):
            m = np.flatnonzero((snap == s) & (link == l) & direct)
            if len(m):
                al = alpha[m].astype(np.complex128)
                pw = np.abs(al) ** 2
                ta = tau[m].astype(np.float64)
                strongest[s] = ta[np.argmax(pw)]
                centroid[s] = np.sum(pw * ta) / np.sum(pw)
                z[s] = al.sum()
        t_rel = np.arange(n_cpi) * spacing
        for k in range(k_scans):
            sl = slice(k * n_cpi, (k + 1) * n_cpi)
            if not np.isnan(strongest[sl][[0, -1]]).any():
                out["fd"][k][l] = float((strongest[sl][-1] - strongest[sl][0]) * C
                                        / ((n_cpi - 1) * spacing))
            steps = np.diff(strongest[sl]) * C / spacing
            steps = steps[~np.isnan(steps)]
            if len(steps):
                out["fd_step"][k][l] = float(np.median(steps))
            ok = ~np.isnan(centroid[sl])
            if ok.sum() >= 2:
                out["centroid"][k][l] = float(np.polyfit(t_rel[ok], centroid[sl][ok] * C, 1)[0])
            m = np.flatnonzero((snap >= k * n_cpi) & (snap < (k + 1) * n_cpi) & (link == l)
                               & direct)
            if len(m):
                pw = np.abs(alpha[m].astype(np.complex128)) ** 2
                out["doppler"][k][l] = float(-lam * np.sum(pw * doppler[m]) / np.sum(pw))
            zz = z[sl]
            r1 = np.sum(zz[1:] * np.conj(zz[:-1]))
            if abs(r1) > 0:
                out["phase"][k][l] = float(-lam * np.angle(r1) / (2 * np.pi * spacing))
    return out


CPI_FIELDS = (("fd", "traced_range_rate_mps", "delay FD of the strongest path"),
              ("fd_step", "traced_range_rate_step_mps", "median step FD of the strongest path"),
              ("centroid", "traced_centroid_range_rate_mps", "slope of the delay centroid"),
              ("doppler", "sionna_doppler_range_rate_mps", "Sionna Doppler"),
              ("phase", "echo_phase_range_rate_mps", "echo phase"))


def run_cpi(out_root, mesh_dir, samples, max_depth, n_cpi, spacing, scans, out_name):
    """Traces the `open` walk in CPI bursts: at each scan start t_k, N snapshots at t_k + n T with
    the body moved to the walk's position at that instant (velocity: the leg's). Writes
    open/<out_name>.npz, open/<out_name>-paths.npz and open/truth-cpi.json (cpi_names)."""
    spec = SCENES["open"]()
    scn = spec["scenario"]
    out = os.path.join(out_root, "open")
    legs, total = walk_legs(**spec["walk"])
    if n_cpi < 2 or not spacing > 0 or not scans:
        raise SystemExit("--cpi: need N >= 2 snapshots, a spacing T > 0 and at least one scan")
    burst = (n_cpi - 1) * spacing
    for k, t0 in enumerate(scans):
        if not 0 <= t0 or t0 + burst >= total:
            raise SystemExit(f"--cpi-scans: scan {t0} s is outside the walk [0, {total:.3f}) s")
        if k and t0 <= scans[k - 1] + burst:
            raise SystemExit(f"--cpi-scans: scan {t0} s starts before scan {scans[k - 1]} s ends")
        leg_of = [next(i for i, lg in enumerate(legs) if lg[0] <= t < lg[1])
                  for t in (t0, t0 + burst)]
        if leg_of[0] != leg_of[1]:
            raise SystemExit(f"--cpi-scans: the CPI at {t0} s spans a turn of the walk")
    os.makedirs(out, exist_ok=True)
    t_s = np.array([t0 + n * spacing for t0 in scans for n in range(n_cpi)])
    states = np.array([walk_state_at(legs, t) for t in t_s])
    t_start = time.time()
    tracer = Tracer(spec, mesh_dir, samples, max_depth)
    tracer.add_body()
    n_links = len(scn["receivers"])
    cfr = np.zeros((len(t_s), n_links, N_BINS), np.complex128)
    # Sionna's own time evolution (Paths.cir/cfr with num_time_steps): the scan's first trace,
    # each path's coefficient turned by e^{j 2 pi f_D,i n T} (delays fixed)
    cfr_dop = np.zeros_like(cfr)
    tx = scn["transmitters"][0]
    info = []
    cols = {k: [] for k in ("snapshot", "link", "tau_s", "alpha", "depth", "doppler_hz")}
    for s, st in enumerate(states):
        tracer.move_body(*st)
        cfr[s], inf = trace_snapshot(tracer, scn, body_paths=True)
        if s % n_cpi == 0:
            for l, d in enumerate(inf):
                g_rx = 10 ** (scn["receivers"][l]["gain_dbi"] / 10)
                for n in range(n_cpi):
                    p = dict(d["kept"])
                    p["a"] = p["a"] * np.exp(2j * np.pi * p["doppler"] * (n * spacing))
                    _, cfr_dop[s + n, l] = link_cfr(p, tx, g_rx)
        for d in inf:
            del d["kept"]
        info.append(inf)
        for l, d in enumerate(inf):
            nb = len(d["body_tau"])
            cols["snapshot"].append(np.full(nb, s, np.uint16))
            cols["link"].append(np.full(nb, l, np.uint8))
            cols["tau_s"].append(d["body_tau"].astype(np.float32))   # Sionna's float32
            cols["alpha"].append(d["body_alpha"].astype(np.complex64))
            cols["depth"].append(d["body_depth"].astype(np.uint8))
            cols["doppler_hz"].append(d["body_doppler"].astype(np.float32))
        if s % n_cpi == 0 or s == len(states) - 1:
            print(f"[cpi] {s + 1}/{len(states)} t={t_s[s]:.6f} s ({time.time() - t_start:.0f} s "
                  f"elapsed) body paths {[len(d['body_tau']) for d in inf]}", flush=True)
    elapsed = time.time() - t_start
    paths = {k: np.concatenate(v) for k, v in cols.items()}

    rec_name, paths_name, truth_name, dop_name = cpi_names(out_name)
    cpi_keys = dict(cpi_snapshots=np.int64(n_cpi), cpi_spacing_s=np.float64(spacing))
    save_npz(os.path.join(out, rec_name), t_s, scn, cfr, extra=cpi_keys)
    save_npz(os.path.join(out, dop_name), t_s, scn, cfr_dop, extra=cpi_keys)
    np.savez_compressed(os.path.join(out, paths_name), **paths)

    txp = np.array([*scn["transmitters"][0]["position_m"], NODE_Z])
    rxps = [np.array([*r["position_m"], NODE_Z]) for r in scn["receivers"]]
    centre_t = [t0 + burst / 2 for t0 in scans]
    scan_states = [walk_state_at(legs, t) for t in centre_t]
    geo = [[round(geometric_range_rate(txp, r, st), 6) for r in rxps] for st in scan_states]
    tr = cpi_traced_rates(n_cpi, spacing, paths["snapshot"], paths["link"], paths["tau_s"],
                          paths["alpha"], paths["depth"], paths["doppler_hz"], n_links, len(t_s))
    rnd = lambda rows: [[r6(v) for v in row] for row in rows]
    pn = noise_power_w(scn)
    gen = generator_info(tracer, spec)
    gen["cpi"] = {"snapshots": n_cpi, "spacing_s": spacing, "scan_start_s": list(scans),
                  "body_velocity": "set on the body (SceneObject.velocity) for Paths.doppler; "
                                   "it does not change a or tau"}
    truth = {
        "t_s": [round(float(t), 9) for t in t_s],
        "states": [[round(float(v), 9) for v in st] for st in states],
        "cpi_snapshots": n_cpi,
        "cpi_spacing_s": spacing,
        "scan_start_s": list(scans),
        "scan_centre_s": [round(t, 9) for t in centre_t],
        "scan_states": [[round(float(v), 9) for v in st] for st in scan_states],
        "noise_var_w": [N_BINS * pn] * n_links,
        "range_rate_point": "body centre (x, y, 0.9 m), nodes at 1.0 m, 3-D unit vectors, at the "
                            "scan's centre time t_k + (N - 1) T / 2",
        "range_rate_mps": geo,
        **{field: rnd(tr[key]) for key, field, _ in CPI_FIELDS},
        "body_paths_file": paths_name,
        "direct_echo_tau_s": [[None if d["direct_echo_m"] is None else d["direct_echo_m"] / C
                               for d in inf] for inf in info],
        "direct_echo_m": [[r6(d["direct_echo_m"]) for d in inf] for inf in info],
        "direct_echo_power_w": [[d["direct_echo_power_w"] for d in inf] for inf in info],
        "echo_m": [[r6(d["echo_m"]) for d in inf] for inf in info],
        "los_m": [[r6(d["los_m"]) for d in inf] for inf in info],
        "paths": [[d["paths"] for d in inf] for inf in info],
        "body_paths": [[d["body_paths"] for d in inf] for inf in info],
        "body_specular_dropped": [[d["dropped"] for d in inf] for inf in info],
        "generator": gen,
    }
    dump_json(os.path.join(out, truth_name), truth)
    digest = hashlib.sha256(cfr.astype(np.complex64).tobytes()).hexdigest()[:16]
    print(f"[cpi] done in {elapsed:.1f} s; {len(t_s)} snapshots; cfr sha256 {digest}", flush=True)
    return elapsed


def report_cpi(out_root, out_name=CPI_OUT, tol=CPI_TOL_MPS):
    """Checks open/<out_name>.npz and its truth: layout, and the range rates recomputed here (the
    geometric one from the states, the traced ones from the per-path file) against the stored
    values and each other. Returns the number of failed checks."""
    rec_name, paths_name, truth_name, dop_name = cpi_names(out_name)
    d = os.path.join(out_root, "open")
    rec = np.load(os.path.join(d, rec_name))
    paths = np.load(os.path.join(d, paths_name))
    truth = json.load(open(os.path.join(d, truth_name)))
    scn = SCENES["open"]()["scenario"]
    n_cpi, spacing = int(rec["cpi_snapshots"]), float(rec["cpi_spacing_s"])
    t_s, cfr = rec["t_s"], rec["cfr"]
    fails = []

    def check(ok, what):
        print(f"  [{'ok' if ok else 'FAIL'}] {what}")
        if not ok:
            fails.append(what)

    n_links = len(scn["receivers"])
    k_scans = len(t_s) // n_cpi
    print(f"== open/{rec_name}: K = {k_scans} scans x N = {n_cpi} snapshots, T = "
          f"{spacing * 1e3:.3f} ms; cfr {cfr.dtype} {list(cfr.shape)}; {paths_name}: "
          f"{len(paths['tau_s'])} body paths")
    check(cfr.dtype == np.complex64 and cfr.shape == (k_scans * n_cpi, n_links, N_BINS),
          "cfr complex64 [K N, 4, 241]")
    check(bool(np.all(np.diff(t_s) > 0)), "t_s strictly increasing")
    check(bool(np.allclose(np.diff(t_s.reshape(k_scans, n_cpi), axis=1), spacing, rtol=0,
                           atol=1e-12)), "T apart within each CPI")
    check(bool(np.array_equal(rec["freq_hz"], FREQ_HZ))
          and rec["links"].tolist() == links_array(scn).tolist(), "freq_hz and links as walk.npz")
    txp = np.array([*scn["transmitters"][0]["position_m"], NODE_Z])
    rxps = [np.array([*r["position_m"], NODE_Z]) for r in scn["receivers"]]
    geo = np.array([[geometric_range_rate(txp, r, st) for r in rxps]
                    for st in truth["scan_states"]])
    check(bool(np.allclose(geo, np.array(truth["range_rate_mps"]), atol=1e-6)),
          "range_rate_mps recomputed from scan_states")
    tr = cpi_traced_rates(n_cpi, spacing, paths["snapshot"], paths["link"], paths["tau_s"],
                          paths["alpha"], paths["depth"], paths["doppler_hz"], n_links, len(t_s))
    arr = lambda rows: np.array([[np.nan if v is None else v for v in row] for row in rows], float)
    for key, field, _ in CPI_FIELDS:
        check(bool(np.allclose(arr(tr[key]), arr(truth[field]), atol=2e-6, equal_nan=True)),
              f"{field} recomputed from {paths_name}")
    lam = C / CARRIER_HZ
    print(f"range rates (m/s) per scan and link; lambda / (2T) = {lam / (2 * spacing):.2f}, "
          f"resolution lambda / (N T) = {lam / (n_cpi * spacing):.2f}")
    print("scan  t_c (s)   vx, vy   | per link: geometric / Sionna Doppler / delay centroid / "
          "echo phase / delay FD of the strongest path")
    rows = {k: arr(tr[k]) for k in tr}
    for k in range(k_scans):
        st = truth["scan_states"][k]
        cells = "  ".join("/".join(f"{v:+.2f}" for v in (
            geo[k, l], rows["doppler"][k, l], rows["centroid"][k, l], rows["phase"][k, l],
            rows["fd"][k, l])) for l in range(n_links))
        print(f"{k:2d} {truth['scan_centre_s'][k]:8.4f} {st[2]:+.2f},{st[3]:+.2f} | {cells}")
    for key, _, label in CPI_FIELDS:
        dev = np.abs(rows[key] - geo)
        print(f"|geometric - {label}|: max {np.nanmax(dev):.3f} m/s, median "
              f"{np.nanmedian(dev):.3f}, rms {np.sqrt(np.nanmean(dev ** 2)):.3f}; within 0.1 / "
              f"0.5 m/s: {np.sum(dev <= 0.1)} / {np.sum(dev <= 0.5)} of "
              f"{np.sum(~np.isnan(dev))} scan-links")
    dev = np.abs(rows["doppler"] - geo)
    check(bool(np.all(dev <= tol)),
          f"|geometric - Sionna Doppler| <= {tol} m/s (max {np.nanmax(dev):.3f})")
    # the recordings themselves: walk minus the empty area (open/empty.npz), Hann window, matched
    # to the direct echo's delay (mean over the CPI), pulse-pair over the N snapshots
    empty = np.load(os.path.join(d, "empty.npz"))["cfr"].astype(np.complex128).mean(0)
    dop = np.load(os.path.join(d, dop_name))
    check(dop["cfr"].shape == cfr.shape and np.array_equal(dop["t_s"], t_s)
          and int(dop["cpi_snapshots"]) == n_cpi, f"{dop_name}: same layout as {rec_name}")
    win = np.hanning(N_BINS + 2)[1:-1]
    echo = arr(truth["direct_echo_m"])
    for label, h in ((rec_name, cfr), (dop_name, dop["cfr"])):
        est = np.full(geo.shape, np.nan)
        for k in range(k_scans):
            for l in range(n_links):
                r = echo[k * n_cpi:(k + 1) * n_cpi, l]
                if np.isnan(r).all():
                    continue
                steer = np.exp(2j * np.pi * FREQ_HZ * np.nanmean(r) / C) * win
                y = (h[k * n_cpi:(k + 1) * n_cpi, l].astype(np.complex128) - empty[l]) @ steer
                est[k, l] = -lam * np.angle(np.sum(y[1:] * np.conj(y[:-1]))) / (2 * np.pi
                                                                                * spacing)
        dev = np.abs(est - geo)
        print(f"{label}: range rate from the CFR (walk - empty at the echo's delay, pulse-pair) "
              f"- geometric: max {np.nanmax(dev):.3f} m/s, median {np.nanmedian(dev):.3f}; "
              f"within {tol} m/s: {np.sum(dev <= tol)}/{np.sum(~np.isnan(dev))}, within 0.5 m/s: "
              f"{np.sum(dev <= 0.5)}")
        print("  " + "; ".join(" ".join(f"{v:+.2f}" for v in row) for row in est))
        if label == dop_name:
            check(bool(np.all(dev <= CPI_CFR_TOL_MPS)), f"{dop_name}: CFR range rate within "
                  f"{CPI_CFR_TOL_MPS} m/s of the geometric one (max {np.nanmax(dev):.3f})")
    still = np.array([st[2] == 0 and st[3] == 0 for st in truth["scan_states"]])
    if still.any():
        zero = np.concatenate([rows[k][still].ravel() for k in rows])
        check(bool(np.all(np.abs(zero) <= 1e-9)),
              "the scans in the stop: every traced range rate is 0 (|.| <= 1e-9 m/s)")
    return len(fails)


# =================================================================================================
# Report (statistics of the written corpus, for the README)
# =================================================================================================

def report(out_root, names):
    for name in names:
        d = os.path.join(out_root, name)
        truth = json.load(open(os.path.join(d, "truth.json")))
        scn = json.load(open(os.path.join(d, "scenario.json")))
        walk = np.load(os.path.join(d, "walk.npz"))
        empty = np.load(os.path.join(d, "empty.npz"))
        pn = noise_power_w(scn)
        db = lambda w: 10 * np.log10(np.asarray(w, float) / pn)
        paths = np.array(truth["paths"])
        diff = np.array(truth["diffuse_paths"])
        body = np.array(truth["body_paths"])
        print(f"== {name}: {len(truth['t_s'])} snapshots; P_n {10 * np.log10(pn) + 30:.2f} dBm")
        print(f"paths per link-snapshot: min {paths.min()} median {np.median(paths):.0f} "
              f"max {paths.max()}; diffuse median {np.median(diff):.0f} "
              f"({np.median(diff / paths) * 100:.1f} %); touching the body min {body.min()} "
              f"median {np.median(body):.0f} max {body.max()}; body-specular left out: "
              f"{np.sum(truth['body_specular_dropped'])} in all")
        print(f"empty area: paths per link {truth['empty']['paths']}, diffuse "
              f"{truth['empty']['diffuse_paths']}")
        tx = scn["transmitters"][0]
        txp = np.array(tx["position_m"])
        lam = C / CARRIER_HZ
        states = np.array(truth["states"])
        for l, rx in enumerate(scn["receivers"]):
            rxp = np.array(rx["position_m"])
            de = [(k, x[l]) for k, x in enumerate(truth["direct_echo_power_w"]) if x[l]]
            e = np.array([v for _, v in de])
            # equivalent bistatic RCS of the direct echo (radar equation, 2-D distances)
            rcs = []
            for k, v in de:
                p = states[k, :2]
                d1, d2 = np.linalg.norm(p - txp), np.linalg.norm(p - rxp)
                g_t = tx_gain_linear(tx, np.arctan2(*(p - txp)[::-1]))
                budget = 10 ** ((tx["power_dbm"] - 30) / 10) * g_t * 10 ** (rx["gain_dbi"] / 10)
                rcs.append(v * (4 * np.pi) ** 3 * d1 ** 2 * d2 ** 2 / (budget * lam ** 2))
            sp = np.array([x[l] for x in truth["echo_power_w"] if x[l]])
            los_e = truth["empty"]["los_power_w"][l]
            shadow = sum(1 for x in truth["los_power_w"] if x[l] is None and los_e is not None)
            print(f"link {l}: direct echo SNR {db(e.min()):.1f} / {np.median(db(e)):.1f} / "
                  f"{db(e.max()):.1f} dB (min/median/max, {len(e)}/{len(paths)} snapshots), "
                  f"equivalent RCS median {10 * np.log10(np.median(rcs)):.1f} dBsm; strongest "
                  f"single body path {db(sp.min()):.1f} / {np.median(db(sp)):.1f} / "
                  f"{db(sp.max()):.1f} dB; LoS SNR {db(los_e):.1f} dB; LoS blocked on "
                  f"{shadow} snapshots")
        for key in ("echo", "direct_echo_m"):
            diffs = np.array([[c - e if e is not None else np.nan for e, c in zip(er, cr)]
                              for er, cr in zip(truth[key], truth["centre_range_m"])])
            print(f"centre range - {key}: median {np.nanmedian(diffs):.3f} m, 5 / 95 % "
                  f"{np.nanpercentile(diffs, 5):.3f} / {np.nanpercentile(diffs, 95):.3f} m, "
                  f"min {np.nanmin(diffs):.3f}, within [0.1, 0.45] m: "
                  f"{np.mean((diffs >= 0.1) & (diffs <= 0.45)) * 100:.1f} % of "
                  f"{np.sum(~np.isnan(diffs))}")
        los_err = [abs(truth["empty"]["los_m"][l] - np.linalg.norm(
            np.array(r["position_m"]) - txp)) for l, r in enumerate(scn["receivers"])]
        print(f"LoS length - |tx - rx| (3-D, equal heights): max {max(los_err) * 1e3:.3f} mm")
        sets = [("noise-free", walk["cfr"])]
        if os.path.exists(os.path.join(d, "walk-noisy.npz")):
            sets.append(("noisy", np.load(os.path.join(d, "walk-noisy.npz"))["cfr"]))
        for label, arr in sets:
            for key in ("echo", "direct_echo_m", "centre_range_m"):
                for top in (1, 3):
                    ok, tot = ifft_check(arr, empty["cfr"], truth[key], top=top)
                    print(f"background-subtracted Hann IFFT: one of the {top} strongest peaks "
                          f"within 0.5 m of {key} ({label}): {ok}/{tot} = {ok / tot:.3f}")


def ifft_check(cfr, empty, ranges, pad=16, top=1):
    """Link-snapshots (with a value in `ranges`) whose strongest peak (or any of the `top`
    strongest local maxima) of |IFFT(Hann (H - mean empty))|, zero-padded 16x, lies within 0.5 m
    of `ranges`: (hits, total)."""
    bg = empty.astype(np.complex128).mean(0)
    win = np.hanning(N_BINS + 2)[1:-1]
    nfft = pad * 256
    # H[n] = sum alpha e^{-j2pi f_n tau}, f_n = (n - 120) df: the IFFT over n peaks at
    # tau mod 1/df (|.| drops the phase of the offset f_0); 1/df = 2 us (602 m), far beyond
    # these scenes
    r_axis = np.arange(nfft) / (nfft * DF) * C
    ok = total = 0
    for k in range(cfr.shape[0]):
        for l in range(cfr.shape[1]):
            if ranges[k][l] is None:
                continue
            y = np.abs(np.fft.ifft((cfr[k, l].astype(np.complex128) - bg[l]) * win, nfft))
            peaks = np.flatnonzero((y > np.roll(y, 1)) & (y >= np.roll(y, -1)))
            best = peaks[np.argsort(y[peaks])[::-1][:top]]
            total += 1
            ok += bool(np.any(np.abs(r_axis[best] - ranges[k][l]) <= 0.5))
    return ok, total


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--scenes", default="open,room")
    ap.add_argument("--out", default=DEFAULT_OUT)
    ap.add_argument("--samples", type=int, default=SAMPLES_PER_SRC)
    ap.add_argument("--max-depth", type=int, default=MAX_DEPTH)
    ap.add_argument("--limit", type=int, default=None, help="trace only the first N snapshots")
    ap.add_argument("--report", action="store_true", help="only print the corpus statistics")
    ap.add_argument("--cpi", nargs="?", const=f"{CPI_SNAPSHOTS},{CPI_SPACING_S}", default=None,
                    metavar="N,T", help="trace only CPI bursts of the open walk: N snapshots "
                    f"T s apart per scan (default {CPI_SNAPSHOTS},{CPI_SPACING_S}); with "
                    "--report, only check the written bursts")
    ap.add_argument("--cpi-scans", default=",".join(str(t) for t in CPI_SCANS), metavar="T0,..",
                    help="start times (s) of the CPI scans")
    ap.add_argument("--cpi-out", default=CPI_OUT, metavar="NAME",
                    help="writes open/NAME.npz, open/NAME-paths.npz and the truth file "
                    "(walk-cpi: truth-cpi.json)")
    args = ap.parse_args()
    names = args.scenes.split(",")
    if args.cpi is not None:
        try:
            n_cpi, spacing = args.cpi.split(",")
            n_cpi, spacing = int(n_cpi), float(spacing)
            scans = [float(t) for t in args.cpi_scans.split(",")]
        except ValueError:
            raise SystemExit(f"--cpi N,T / --cpi-scans T0,..: cannot parse {args.cpi!r} / "
                             f"{args.cpi_scans!r}")
        if not args.report:
            mesh_dir = tempfile.mkdtemp(prefix="scatterloc-raytrace-")
            try:
                run_cpi(args.out, mesh_dir, args.samples, args.max_depth, n_cpi, spacing, scans,
                        args.cpi_out)
            finally:
                shutil.rmtree(mesh_dir, ignore_errors=True)
        return 1 if report_cpi(args.out, args.cpi_out) else 0
    if not args.report:
        mesh_dir = tempfile.mkdtemp(prefix="scatterloc-raytrace-")
        try:
            t0 = time.time()
            for n in names:
                run_scene(n, args.out, mesh_dir, args.samples, args.max_depth, args.limit)
            print(f"total {time.time() - t0:.1f} s", flush=True)
        finally:
            shutil.rmtree(mesh_dir, ignore_errors=True)
    report(args.out, names)
    if "open" in names and os.path.exists(os.path.join(args.out, "open",
                                                       cpi_names(args.cpi_out)[0])):
        return 1 if report_cpi(args.out, args.cpi_out) else 0


if __name__ == "__main__":
    sys.exit(main())
