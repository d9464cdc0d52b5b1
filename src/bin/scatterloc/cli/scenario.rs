//! Flags of the single-snapshot commands: `preset`, `crlb`, `crlb-map`, `locate`.

use clap::Args;

use super::values::{finite, whole, xy};

/// `scatterloc preset NAME`.
#[derive(Debug, Args)]
pub struct PresetArgs {
    /// The preset: sensors2019 (the [S] layout L4: one Tx, four Rx, 5.8 GHz) or iclgnss2019.
    #[arg(value_name = "NAME")]
    pub name: String,
}

/// `scatterloc crlb`.
#[derive(Debug, Args)]
pub struct CrlbArgs {
    /// Scenario JSON file ('-' = standard input), e.g. the output of `scatterloc preset`.
    #[arg(long, value_name = "FILE")]
    pub scenario: String,
    /// The point, metres: X,Y (e.g. 10,0).
    #[arg(long, value_name = "X,Y", value_parser = xy)]
    pub at: [f64; 2],
    /// The bound over [x, y, z] with the target's height unknown (nodes at their heights;
    /// docs/rooms-3d.md): sigma_z_m, the 3-D RMSE bound and, beside it, the horizontal bound with
    /// the height known.
    #[arg(long)]
    pub free_z: bool,
    /// With --free-z: the target's height Z, metres [default: the scenario's target.height_m].
    #[arg(long, value_name = "Z", value_parser = finite, requires = "free_z")]
    pub height: Option<f64>,
    /// The Doppler flags (`--doppler` and its CPI).
    #[command(flatten)]
    pub doppler: DopplerArgs,
}

/// `scatterloc crlb-map`.
#[derive(Debug, Args)]
pub struct CrlbMapArgs {
    /// Scenario JSON file ('-' = standard input).
    #[arg(long, value_name = "FILE")]
    pub scenario: String,
    /// Output file; the extension picks the format: .json (the values), .svg or .png (figure).
    #[arg(long, value_name = "OUT.{json,svg,png}")]
    pub out: String,
    /// Grid cells along x, 2..=4096 [default: 256].
    #[arg(long, value_name = "N", value_parser = whole)]
    pub nx: Option<usize>,
    /// Grid cells along y, 2..=4096 [default: 256]; nx * ny at most 4194304.
    #[arg(long, value_name = "N", value_parser = whole)]
    pub ny: Option<usize>,
    /// Left edge of the grid, m [default: area_m.x[0] of the scenario].
    #[arg(long, value_name = "A", value_parser = finite)]
    pub x_min: Option<f64>,
    /// Right edge of the grid, m [default: area_m.x[1] of the scenario].
    #[arg(long, value_name = "B", value_parser = finite)]
    pub x_max: Option<f64>,
    /// Bottom edge of the grid, m [default: area_m.y[0] of the scenario].
    #[arg(long, value_name = "C", value_parser = finite)]
    pub y_min: Option<f64>,
    /// Top edge of the grid, m [default: area_m.y[1] of the scenario].
    #[arg(long, value_name = "D", value_parser = finite)]
    pub y_max: Option<f64>,
    /// Figure width, pixels, 200..=8000 [default: 1000] (.svg/.png only).
    #[arg(long, value_name = "PX", value_parser = whole)]
    pub width: Option<usize>,
    /// Figure height, pixels, 150..=8000 [default: from the width and the area's aspect ratio].
    #[arg(long, value_name = "PX", value_parser = whole)]
    pub height: Option<usize>,
    /// Figure title [default: the scenario's name and the bound plotted].
    #[arg(long, value_name = "TEXT")]
    pub title: Option<String>,
    /// What the map shows: `position` (the RMSE bound, m) or `velocity` (the velocity's RMSE
    /// bound, m/s; needs --doppler).
    #[arg(long, value_parser = ["position", "velocity"], default_value = "position")]
    pub quantity: String,
    /// The Doppler flags: with --doppler the bounds include every link's range rate.
    #[command(flatten)]
    pub doppler: DopplerArgs,
}

/// `scatterloc locate`.
#[derive(Debug, Args)]
pub struct LocateArgs {
    /// Scenario JSON file ('-' = standard input).
    #[arg(long, value_name = "FILE")]
    pub scenario: String,
    /// Delays JSON file ('-' = standard input): {"delays_s": [..], "sigma_s": .., "initial_m": [x, y]}.
    #[arg(long, value_name = "FILE")]
    pub delays: String,
    /// Fix [x, y, z] with the target's height unknown (LM over three unknowns from the planar fix
    /// at the scenario's target height; "initial_m" may then be [x, y, z]; docs/rooms-3d.md).
    #[arg(long)]
    pub free_z: bool,
}

/// `--doppler` and its CPI, shared by `crlb`, `crlb-map` and `track` (docs/doppler.md, D1–D7;
/// `track` reads only the CPI: the σ of the measurement file's range rates).
#[derive(Debug, Args)]
pub struct DopplerArgs {
    /// The bound from every link's delay and range rate over one coherent processing interval
    /// (CPI); `crlb` adds the document `doppler`, `crlb-map` maps it (see --quantity); `track`
    /// takes its range rates' sigma from this CPI.
    #[arg(long = "doppler")]
    pub on: bool,
    /// With --doppler: the target's velocity VX,VY, m/s (the range rates' gradients depend on it).
    #[arg(long, value_name = "VX,VY", value_parser = xy, requires = "on", default_value = "0,0")]
    pub velocity: [f64; 2],
    /// With --doppler: snapshots N in the CPI.
    #[arg(long, value_name = "N", requires = "on", default_value_t = 16)]
    pub cpi: usize,
    /// With --doppler: the snapshots' spacing T, seconds (default: a 2.048 ms sounder frame).
    #[arg(long, value_name = "T", value_parser = finite, requires = "on", default_value_t = 2.048e-3)]
    pub cpi_spacing_s: f64,
    /// With --doppler: the floor on the range rate's σ, m/s (D5: a body's limbs move).
    #[arg(long, value_name = "F", value_parser = finite, requires = "on",
          default_value_t = scatterloc::measure::DEFAULT_RANGE_RATE_FLOOR_MPS)]
    pub range_rate_floor: f64,
}
