//! Which registers a native CRLB map runs on (issue 29): the core's portable kernel
//! ([`wide::f64x4`]: two SSE2 registers on any x86-64, AVX on CPUs without AVX2) or, chosen at
//! run time when this CPU has them, AVX2 + FMA or AVX-512 ([`super::lanes`]), exact (the core's
//! bits) or fast (within the bound stated there). `SCATTERLOC_MAP_PATH` (`portable`, `avx2`,
//! `avx2-fast`, `avx512`, `avx512-fast`) pins the path of the fast maps for a comparison; a
//! path this CPU lacks is ignored.

use std::sync::OnceLock;
use std::vec::Vec;

use crate::error::Result;
use crate::localize::{crlb_map_rows, crlb_map_rows_with, Grid};
use crate::math::Real;
use crate::measure::Model;

/// A kernel path.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum MapPath {
    /// The core's kernel on [`wide::f64x4`] (every CPU; the scalar reference's bits).
    Portable,
    /// AVX2 registers, the scalar reference's operations (its bits).
    Avx2,
    /// AVX2 with FMA and the `1/√d²` estimate (within the stated bound).
    Avx2Fast,
    /// AVX-512 registers, the scalar reference's operations (its bits).
    Avx512,
    /// AVX-512 with FMA and `vrsqrt14pd` (within the stated bound).
    Avx512Fast,
}

impl MapPath {
    /// Every path, slowest first.
    pub const ALL: [MapPath; 5] = [
        MapPath::Portable,
        MapPath::Avx2,
        MapPath::Avx2Fast,
        MapPath::Avx512,
        MapPath::Avx512Fast,
    ];

    /// `portable`, `avx2`, `avx2-fast`, `avx512`, `avx512-fast`.
    pub fn name(self) -> &'static str {
        match self {
            MapPath::Portable => "portable",
            MapPath::Avx2 => "avx2",
            MapPath::Avx2Fast => "avx2-fast",
            MapPath::Avx512 => "avx512",
            MapPath::Avx512Fast => "avx512-fast",
        }
    }

    /// Whether the path returns the scalar reference's bits.
    pub fn exact(self) -> bool {
        !matches!(self, MapPath::Avx2Fast | MapPath::Avx512Fast)
    }

    /// Whether this CPU (and this build) can run the path.
    pub fn available(self) -> bool {
        match self {
            MapPath::Portable => true,
            #[cfg(target_arch = "x86_64")]
            MapPath::Avx2 | MapPath::Avx2Fast => pulp::x86::V3::try_new().is_some(),
            #[cfg(target_arch = "x86_64")]
            MapPath::Avx512 | MapPath::Avx512Fast => pulp::x86::V4::try_new().is_some(),
            #[cfg(not(target_arch = "x86_64"))]
            _ => false,
        }
    }
}

/// The paths this CPU can run, slowest first.
pub fn map_paths() -> Vec<MapPath> {
    MapPath::ALL.into_iter().filter(|p| p.available()).collect()
}

/// The path of [`crlb_map_fast`] (the fastest this CPU has, or `SCATTERLOC_MAP_PATH`).
pub fn fast_path() -> MapPath {
    static PATH: OnceLock<MapPath> = OnceLock::new();
    *PATH.get_or_init(|| {
        let pinned = std::env::var("SCATTERLOC_MAP_PATH").ok();
        let paths = map_paths();
        pinned
            .and_then(|name| paths.iter().copied().find(|p| p.name() == name))
            .unwrap_or_else(|| {
                [MapPath::Avx512Fast, MapPath::Avx2Fast]
                    .into_iter()
                    .find(|p| p.available())
                    .unwrap_or(MapPath::Portable)
            })
    })
}

/// The path of [`crlb_map_exact`]: the widest exact one this CPU has.
pub fn exact_path() -> MapPath {
    static PATH: OnceLock<MapPath> = OnceLock::new();
    *PATH.get_or_init(|| {
        [MapPath::Avx512, MapPath::Avx2]
            .into_iter()
            .find(|p| p.available())
            .unwrap_or(MapPath::Portable)
    })
}

/// [`crate::localize::crlb_map_rows`] on `path` (the portable kernel when this CPU lacks it).
pub fn crlb_map_rows_on(
    path: MapPath,
    model: &Model,
    grid: &Grid,
    first_row: usize,
    out: &mut [Real],
) -> Result<()> {
    #[cfg(target_arch = "x86_64")]
    {
        use super::lanes::{Avx2, Avx512};
        use pulp::x86::{V3, V4};
        let fast = !path.exact();
        match path {
            MapPath::Avx2 | MapPath::Avx2Fast => {
                if let Some(s) = V3::try_new() {
                    return on::<_, Avx2<false>, Avx2<true>>(s, fast, model, grid, first_row, out);
                }
            }
            MapPath::Avx512 | MapPath::Avx512Fast => {
                if let Some(s) = V4::try_new() {
                    return on::<_, Avx512<false>, Avx512<true>>(
                        s, fast, model, grid, first_row, out,
                    );
                }
            }
            MapPath::Portable => {}
        }
    }
    let _ = path;
    crlb_map_rows(model, grid, first_row, out)
}

/// The kernel on the exact or the fast `Lanes` type of one instruction set `S`.
#[cfg(target_arch = "x86_64")]
fn on<S, Exact, Fast>(
    arch: S,
    fast: bool,
    model: &Model,
    grid: &Grid,
    first_row: usize,
    out: &mut [Real],
) -> Result<()>
where
    S: pulp::Simd,
    Exact: crate::math::Lanes<Arch = S>,
    Fast: crate::math::Lanes<Arch = S>,
{
    let rows = Rows {
        arch,
        model,
        grid,
        first_row,
        out,
    };
    if fast {
        arch.vectorize(Kernel::<Fast>(rows))
    } else {
        arch.vectorize(Kernel::<Exact>(rows))
    }
}

/// The arguments of one kernel call.
#[cfg(target_arch = "x86_64")]
struct Rows<'a, A> {
    arch: A,
    model: &'a Model,
    grid: &'a Grid,
    first_row: usize,
    out: &'a mut [Real],
}

/// The kernel on `L` as a call `vectorize` compiles with `L`'s target features: `call` and
/// everything under it is `#[inline(always)]`, so the vector operations inline (a closure body
/// would not be forced inline, and its intrinsics would become calls).
#[cfg(target_arch = "x86_64")]
struct Kernel<'a, L: crate::math::Lanes>(Rows<'a, L::Arch>);

#[cfg(target_arch = "x86_64")]
impl<L: crate::math::Lanes> pulp::NullaryFnOnce for Kernel<'_, L> {
    type Output = Result<()>;

    #[inline(always)]
    fn call(self) -> Result<()> {
        let r = self.0;
        crlb_map_rows_with::<L>(r.arch, r.model, r.grid, r.first_row, r.out)
    }
}

/// The whole map on `path`, one thread.
pub fn crlb_map_on(path: MapPath, model: &Model, grid: &Grid, out: &mut [Real]) -> Result<()> {
    crate::error::check_len("map buffer", grid.len(), out.len())?;
    crlb_map_rows_on(path, model, grid, 0, out)
}

/// The map on this CPU's fastest path ([`fast_path`]), one thread: within the bound of
/// [`super::lanes`] of the core's kernel.
pub fn crlb_map_fast(model: &Model, grid: &Grid, out: &mut [Real]) -> Result<()> {
    crlb_map_on(fast_path(), model, grid, out)
}

/// The map on this CPU's widest exact path ([`exact_path`]), one thread: the core kernel's
/// bits ([`crate::localize::crlb_map`]), so the planner's results never depend on the CPU.
pub fn crlb_map_exact(model: &Model, grid: &Grid, out: &mut [Real]) -> Result<()> {
    crlb_map_on(exact_path(), model, grid, out)
}
