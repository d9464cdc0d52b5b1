//! Tracking a moving scatterer: the white-noise-acceleration motion model (E7), the EKF with the
//! Joseph-form update (spec §6, S16–S17), the UKF and the bootstrap particle filter
//! (`filters-and-planning.md` §1–2) behind one seam ([`Filter`], driven through [`Tracker`];
//! the trait is their API) with their shared helpers in one private module (`shared`), the
//! posterior CRLB recursion (E9, §8), the trajectories of \[S\] Fig. 2b and the Monte Carlo
//! prior (§9.4–9.5), one simulated run for display, the raw-estimate front end (`gating`: spec
//! §4, C7, C11), and the Monte Carlo study of the tracker against its bound, chunked so that any
//! driver (sequential, `native`, the page's worker) gives the same result; and the GOSPA metric
//! that scores a multi-target estimate (issue 41).

mod cost;
mod doppler;
mod ekf;
mod filter;
pub mod gating;
mod gospa;
mod montecarlo;
mod motion;
pub mod multi;
mod pcrlb;
mod pf;
mod shared;
mod track_sim;
mod trajectory;
mod ukf;

pub use cost::{
    step_ns, step_ns_doppler, EKF_DOPPLER_NS, EKF_DOPPLER_NS_PER_LINK, EKF_NS, EKF_NS_PER_LINK,
    PF_NS_PER_LINK3, PF_NS_PER_PARTICLE, PF_NS_PER_PARTICLE_LINK, PF_NS_PER_PARTICLE_LINK2, UKF_NS,
    UKF_NS_PER_LINK, UKF_NS_PER_LINK2, UKF_NS_PER_LINK3,
};
pub use doppler::{PredictedRate, RangeRates, RateNoise};
pub(crate) use ekf::update_lanes;
pub use ekf::Ekf;
pub use filter::{step_doppler, Filter, FilterKind, FilterSettings, Tracker};
pub use gospa::{gospa, Gospa, GospaConfig, MAX_GOSPA_POINTS};
pub use montecarlo::{
    finish, pcrlb_from_sums, run_chunk, run_chunk_in, run_filter_chunk, run_filter_chunk_in,
    run_pcrlb_sequential, run_sequential, run_truth_chunk, MonteCarloConfig, MonteCarloResult,
    PartialSums, StudySums, CHUNK_TRAJECTORIES, MAX_RUNS, MAX_STEPS,
};
pub use motion::ConstantVelocity;
pub use pcrlb::{nominal_pcrlb_rmse, nominal_pcrlb_state, pcrlb_rmse, PosteriorInformation};
pub use pf::{
    kernel_bandwidth, ParticleFilter, PfConfig, PfUpdate, MAX_PARTICLES, PROPOSAL_INFLATION,
};
pub use shared::{check_covariance, MeasurementNoise, PredictedDelay, UpdateSummary};
pub(crate) use shared::{range_information_per_snr, spd_quadratic_form, NodeView};
pub use track_sim::{simulate_track, TrackRun};
pub use trajectory::{
    paper_initial_covariance, step_count, TrackScenario, TruthSampler, DEFAULT_STUDY_SEED,
    PAPER_DURATION_S, PAPER_INTENSITY, PAPER_NOISE_RUNS, PAPER_RUNS, PAPER_STEP_S,
};
pub use ukf::{
    Ukf, UkfParams, ALPHA_RANGE as UKF_ALPHA_RANGE, MAX_PRIOR_VARIANCE as UKF_MAX_PRIOR_VARIANCE,
};
