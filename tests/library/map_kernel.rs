#![cfg(not(target_arch = "wasm32"))]
//! The SIMD CRLB map kernel against its scalar reference (issue 13 §1): random scenarios with
//! omni and beam patterns (with and without the gain polynomial), 1–64 links, bounded and
//! unbounded cells, cells exactly on nodes and row lengths that are not a multiple of the vector
//! width. The kernel performs the reference's operations in the same order, so the derived bound
//! is zero: the maps must agree bitwise. Row blocks and the threaded map must equal the
//! single-call map bitwise too (rows are independent).

use rand::{Rng, SeedableRng};
use rand_pcg::Pcg64;
use scatterloc::localize::{
    crlb_at, crlb_map, crlb_map_rows, crlb_map_scalar, Grid, SINGULAR_RCOND,
};
use scatterloc::math::{Real, Vec2};
use scatterloc::scenario::{presets, Area, LinkSpec, Pattern, Receiver, Scenario, Transmitter};
use scatterloc::Model;

/// Random scenarios per seed group.
const SCENARIOS: u64 = 400;

/// Which pattern family a transmitter gets.
fn pattern(rng: &mut Pcg64) -> Pattern {
    match rng.random_range(0..3) {
        0 => Pattern::Omni,
        // A beam the gain polynomial fits.
        1 => Pattern::Parabolic {
            boresight_deg: rng.random_range(-180.0..180.0),
            beamwidth_deg: rng.random_range(10.0..120.0),
            floor_db: rng.random_range(3.0..30.0),
        },
        // A floor so deep that the fit interval reaches c = −1: no polynomial, exact formula.
        _ => Pattern::Parabolic {
            boresight_deg: rng.random_range(-180.0..180.0),
            beamwidth_deg: rng.random_range(120.0..170.0),
            floor_db: rng.random_range(60.0..100.0),
        },
    }
}

/// A random scenario: 1–8 transmitters, 1–8 receivers, a random subset of 1–64 links; with some
/// probability all nodes on one line (unbounded cells on it), a single link (unbounded
/// everywhere) or an area whose cell centres fall on a node.
fn random_case(seed: u64) -> (Scenario, Grid) {
    let mut rng = Pcg64::seed_from_u64(seed);
    let mut s = presets::sensors2019();
    let collinear = rng.random_bool(0.15);
    let node = |rng: &mut Pcg64| {
        let x = rng.random_range(-30.0..30.0);
        let y = if collinear {
            0.0
        } else {
            rng.random_range(-30.0..30.0)
        };
        [x, y]
    };
    let (k, l) = (rng.random_range(1..=8usize), rng.random_range(1..=8usize));
    s.transmitters = (0..k)
        .map(|i| Transmitter {
            name: format!("Tx{i}"),
            height_m: 0.0,
            position_m: node(&mut rng),
            power_dbm: rng.random_range(0.0..40.0),
            gain_dbi: rng.random_range(0.0..15.0),
            pattern: pattern(&mut rng),
        })
        .collect();
    s.receivers = (0..l)
        .map(|i| Receiver {
            name: format!("Rx{i}"),
            height_m: 0.0,
            position_m: node(&mut rng),
            gain_dbi: rng.random_range(0.0..15.0),
        })
        .collect();
    let mut pairs: Vec<[String; 2]> = (0..k)
        .flat_map(|t| (0..l).map(move |r| [format!("Tx{t}"), format!("Rx{r}")]))
        .filter(|_| rng.random_bool(0.7))
        .collect();
    if pairs.is_empty() || rng.random_bool(0.1) {
        pairs = vec![["Tx0".into(), "Rx0".into()]];
    }
    s.links = LinkSpec::List(pairs);
    let (nx, ny) = (rng.random_range(2..=37usize), rng.random_range(2..=23usize));
    s.area_m = if rng.random_bool(0.3) {
        // Odd sizes around a node: the middle cell centre is exactly on it.
        let c = s.receivers[0].position_m;
        let (hx, hy) = (rng.random_range(1.0..20.0), rng.random_range(1.0..20.0));
        Area {
            x: [c[0] - hx, c[0] + hx],
            y: [c[1] - hy, c[1] + hy],
        }
    } else {
        Area {
            x: [-40.0, rng.random_range(-20.0..40.0)],
            y: [rng.random_range(-40.0..0.0), 35.0],
        }
    };
    let (nx, ny) = if collinear {
        (nx, ny | 1)
    } else {
        (nx | 1, ny | 1)
    };
    let grid = Grid::new(s.area_m, nx, ny).unwrap();
    (s, grid)
}

fn map(
    f: fn(&Model, &Grid, &mut [Real]) -> scatterloc::Result<()>,
    m: &Model,
    g: &Grid,
) -> Vec<Real> {
    let mut out = vec![Real::NAN; g.len()];
    f(m, g, &mut out).unwrap();
    out
}

fn assert_bitwise(what: &str, got: &[Real], want: &[Real]) {
    assert_eq!(got.len(), want.len());
    for (i, (g, w)) in got.iter().zip(want).enumerate() {
        assert!(
            g.to_bits() == w.to_bits(),
            "{what}: cell {i}: {g:e} vs {w:e}"
        );
    }
}

#[test]
fn simd_kernel_equals_scalar_reference_bitwise() {
    let (mut bounded, mut unbounded, mut no_poly, mut beams, mut max_links) = (0, 0, 0, 0, 0);
    for seed in 0..SCENARIOS {
        let (s, grid) = random_case(seed);
        let m = Model::new(&s).unwrap();
        let simd = map(crlb_map, &m, &grid);
        let scalar = map(crlb_map_scalar, &m, &grid);
        assert_bitwise(&format!("seed {seed}"), &simd, &scalar);
        assert!(simd.iter().all(|v| !v.is_nan() && *v > 0.0), "seed {seed}");
        bounded += simd.iter().filter(|v| v.is_finite()).count();
        unbounded += simd.iter().filter(|v| v.is_infinite()).count();
        beams += m.patterns.iter().filter(|p| p.beam.is_some()).count();
        no_poly += m
            .patterns
            .iter()
            .filter(|p| p.beam.is_some() && p.polynomial.is_none())
            .count();
        max_links = max_links.max(m.network.links.len());
    }
    // The random cases really cover what the comparison is about.
    assert!(
        bounded > 10_000 && unbounded > 1_000,
        "{bounded} bounded, {unbounded} unbounded"
    );
    assert!(
        beams > 200 && no_poly > 50,
        "{beams} beams, {no_poly} without polynomial"
    );
    assert!(max_links >= 40, "largest link count {max_links}");
}

#[test]
fn simd_kernel_matches_crlb_at_on_random_scenarios() {
    // The point evaluation is an independent path (nalgebra, per-link gain, another summation
    // order). Reordered sums of F differ by a few ulps of its entries; √(tr/det) then differs by
    // about κ·ε relative, κ = tr²/det the condition number: tolerance 1e-12 + 64·κ·ε. Cells
    // within a factor 2 of the singular threshold may fall on either side of it.
    let mut compared = 0;
    for seed in 0..SCENARIOS / 4 {
        let (s, grid) = random_case(1_000 + seed);
        let m = Model::new(&s).unwrap();
        let simd = map(crlb_map, &m, &grid);
        for j in 0..grid.ny {
            for i in 0..grid.nx {
                let v = simd[j * grid.nx + i];
                let p = crlb_at(&m, Vec2::new(grid.x(i), grid.y(j)));
                let f = p.fisher_per_m2;
                let (tr, det) = (
                    f[(0, 0)] + f[(1, 1)],
                    f[(0, 0)] * f[(1, 1)] - f[(0, 1)] * f[(1, 0)],
                );
                let near_threshold = det < 2.0 * SINGULAR_RCOND * tr * tr;
                match p.bound {
                    Some(b) if v.is_finite() => {
                        let kappa = tr * tr / det;
                        let tol = 1e-12 + 64.0 * kappa * Real::EPSILON;
                        assert!(
                            (v - b.rmse_m).abs() <= tol * b.rmse_m,
                            "seed {seed} cell ({i},{j}): {v} vs {}, κ {kappa:e}",
                            b.rmse_m
                        );
                        compared += 1;
                    }
                    Some(_) => assert!(near_threshold, "seed {seed} ({i},{j}): map unbounded"),
                    None => assert!(
                        v.is_infinite() || near_threshold || tr <= 0.0 || tr.is_nan(),
                        "seed {seed} ({i},{j}): map {v}, crlb_at unbounded"
                    ),
                }
            }
        }
    }
    assert!(compared > 5_000, "{compared} bounded cells compared");
}

#[test]
fn row_blocks_and_threads_equal_the_whole_map() {
    for seed in 0..40 {
        let (s, grid) = random_case(2_000 + seed);
        let m = Model::new(&s).unwrap();
        let whole = map(crlb_map, &m, &grid);
        // Any split into row blocks.
        let mut out = vec![Real::NAN; grid.len()];
        let mut row = 0;
        for block in out.chunks_mut(3 * grid.nx) {
            crlb_map_rows(&m, &grid, row, block).unwrap();
            row += block.len() / grid.nx;
        }
        assert_bitwise("row blocks", &out, &whole);
    }
    // Threads from 128² cells up: bitwise the single-threaded map of the same kernel path (the
    // fastest this CPU has, issue 29) for 1, 2 and 3 workers.
    let s = presets::sensors2019();
    let m = Model::new(&s).unwrap();
    let grid = Grid::new(s.area_m, 131, 129).unwrap();
    let fast = |m: &Model, g: &Grid, o: &mut [Real]| {
        scatterloc::native::crlb_map_on(scatterloc::native::fast_path(), m, g, o)
    };
    let whole = map(fast, &m, &grid);
    for threads in [0, 1, 2, 3] {
        let mut out = vec![Real::NAN; grid.len()];
        scatterloc::native::crlb_map_parallel(&m, &grid, &mut out, threads).unwrap();
        assert_bitwise(&format!("{threads} threads"), &out, &whole);
    }
}

#[test]
fn row_ranges_outside_the_grid_are_errors() {
    let s = presets::sensors2019();
    let m = Model::new(&s).unwrap();
    let grid = Grid::new(s.area_m, 8, 4).unwrap();
    let mut two_rows = vec![0.0; 16];
    assert!(crlb_map_rows(&m, &grid, 2, &mut two_rows).is_ok());
    assert!(crlb_map_rows(&m, &grid, 3, &mut two_rows).is_err());
    let mut ragged = vec![0.0; 12];
    assert!(crlb_map_rows(&m, &grid, 0, &mut ragged).is_err());
    // A whole number of rows that is not the whole grid is still the wrong buffer for a map.
    let mut three_rows = vec![0.0; 24];
    assert!(crlb_map(&m, &grid, &mut three_rows).is_err());
    let mut whole = vec![0.0; 31];
    assert!(scatterloc::native::crlb_map_parallel(&m, &grid, &mut whole, 0).is_err());
}

/// Issue 29: every kernel path this CPU has against the core's kernel. The exact paths (AVX2,
/// AVX-512 with the reference's IEEE operations) must equal it bitwise; the fast ones (FMA,
/// `1/√d²` from the hardware estimate and Newton steps) within the derived bound
/// `64·ε·κ·(Γ + S + G)` relative: a few ulps per unit-vector component, amplified by the
/// cancellation in `g = u^Tx + u^Rx` (`Γ = Σ w|g| / Σ w|g|²`, ≥ 1/2, large when the cell lies
/// near the baselines that carry its information), by the beams' sensitivity to the direction
/// (`S = 2kψ_f/sin ψ_f`, the largest `|d ln G/d cos ψ|` of a beam `G₀·exp(−kψ²)` inside its floor
/// angle ψ_f: a narrow beam turns an ulp of the unit vector into hundreds of ulps of gain), by
/// the gain polynomial's conditioning (`G = n·Σ|c_k| / g_floor`) and by `κ = tr²/det`, the
/// Fisher matrix's condition number (module doc of `native::lanes`); bounded and unbounded
/// cells agree except within a factor 2 of the singular threshold. Which paths ran is printed
/// (a CPU without AVX-512 runs fewer).
#[test]
fn every_dispatched_path_agrees_with_the_core_kernel() {
    use scatterloc::native::{crlb_map_on, map_paths};
    let paths = map_paths();
    println!(
        "kernel paths on this CPU: {}",
        paths
            .iter()
            .map(|p| p.name())
            .collect::<Vec<_>>()
            .join(", ")
    );
    let (mut worst, mut worst_plain, mut compared) = (0.0f64, 0.0f64, 0usize);
    let (mut above, mut kappa_above) = (0usize, Real::INFINITY);
    for seed in 0..SCENARIOS {
        let (s, grid) = random_case(3_000 + seed);
        let m = Model::new(&s).unwrap();
        let reference = map(crlb_map, &m, &grid);
        let gain_amp = m
            .patterns
            .iter()
            .filter_map(|p| p.polynomial.as_ref())
            .map(|p| {
                let sum: Real = p.coefficients.iter().map(|c| c.abs()).sum();
                p.coefficients.len() as Real * sum / p.floor_gain
            })
            .fold(0.0, Real::max);
        let beam_sens = m
            .patterns
            .iter()
            .filter_map(|p| p.beam)
            .map(|b| {
                let psi = b.floor_angle_rad.min(std::f64::consts::PI);
                2.0 * b.exponent_per_rad2 * psi / psi.sin().max(1e-3)
            })
            .fold(0.0, Real::max);
        for &path in &paths {
            let mut out = vec![Real::NAN; grid.len()];
            crlb_map_on(path, &m, &grid, &mut out).unwrap();
            if path.exact() {
                assert_bitwise(&format!("{} seed {seed}", path.name()), &out, &reference);
                continue;
            }
            for j in 0..grid.ny {
                for i in 0..grid.nx {
                    let (v, r) = (out[j * grid.nx + i], reference[j * grid.nx + i]);
                    assert!(!v.is_nan() && v > 0.0, "{} seed {seed}: {v}", path.name());
                    let at = Vec2::new(grid.x(i), grid.y(j));
                    let f = crlb_at(&m, at).fisher_per_m2;
                    // Γ from each link's information and |g| = c·|∇τ| (E3, E8).
                    let (mut num, mut den) = (0.0, 0.0);
                    for p in 0..m.link_count() {
                        let w = m.delay_information(p, at);
                        let g = m.network.jacobian_row(p, at).norm() * 299_792_458.0;
                        num += w * g;
                        den += w * g * g;
                    }
                    let gamma = if den > 0.0 { num / den } else { Real::INFINITY };
                    let (tr, det) = (
                        f[(0, 0)] + f[(1, 1)],
                        f[(0, 0)] * f[(1, 1)] - f[(0, 1)] * f[(1, 0)],
                    );
                    let near_threshold = det < 2.0 * SINGULAR_RCOND * tr * tr;
                    if v.is_finite() && r.is_finite() {
                        let kappa = tr * tr / det;
                        let rel = (v - r).abs() / r;
                        let amp = kappa * (gamma + beam_sens + gain_amp);
                        let bound = 64.0 * Real::EPSILON * amp;
                        assert!(
                            rel <= bound,
                            "{} seed {seed} ({i},{j}): {v} vs {r}: {rel:e} > {bound:e} (κ {kappa:e}, Γ {gamma:e}, S {beam_sens:e}, G {gain_amp:e})",
                            path.name()
                        );
                        worst = worst.max(rel / (Real::EPSILON * amp));
                        worst_plain = worst_plain.max(rel);
                        if rel > 1e-12 {
                            above += 1;
                            kappa_above = kappa_above.min(kappa);
                        }
                        compared += 1;
                    } else {
                        assert!(
                            v == r || near_threshold,
                            "{} seed {seed} ({i},{j}): {v} vs {r}",
                            path.name()
                        );
                    }
                }
            }
        }
    }
    println!(
        "fast paths: {compared} bounded cells; largest relative deviation {worst_plain:e}, \
         largest deviation / (ε·κ·(Γ + S + G)) {worst:.2}; {above} cells beyond 1e-12 (κ ≥ \
         {kappa_above:e})"
    );
}
