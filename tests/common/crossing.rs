//! The recording of issue 41 §3, "two simulated walkers who cross" (signal level), shared by
//! the library's test (`tests/tracking/cir_multi.rs`) and the CLI's (`tests/cli/cir_multi.rs`).
//!
//! The sensors2019 hangar's nodes in a room of four walls (Γ = −0.5, first- and second-order
//! reflections, shadowing; no body–wall double reflections: with them the tracker confirms
//! their echoes as further people, see the tests' notes), walker 0 from (13, −2) to (20, 4)
//! and walker 1 from (12.09, 4.78) to (20, −2), both at 1.2 m/s: their paths cross at
//! (16.5, 1), walker 0 there at 3.84 s and walker 1 one second later (their closest approach
//! ≈ 0.8 m); 20 Hz snapshots for 8.7 s, 1 s of the empty area.

use serde_json::{json, Value};

/// Where the walkers' paths cross, m.
#[allow(dead_code)] // the library's test reads it, the CLI's does not
pub const CROSSING_M: [f64; 2] = [16.5, 1.0];

/// The scene file (`cir simulate --scene`).
pub fn crossing_scene() -> Value {
    let wall = |a: [f64; 2], b: [f64; 2]| json!({"a_m": a, "b_m": b, "gamma": -0.5});
    json!({
        "walls": [
            wall([-8.0, -10.0], [24.0, -10.0]),
            wall([24.0, -10.0], [24.0, 16.0]),
            wall([24.0, 16.0], [-8.0, 16.0]),
            wall([-8.0, 16.0], [-8.0, -10.0]),
        ],
        "walk": {"waypoints_m": [[13.0, -2.0], [20.0, 4.0]], "speed_mps": 1.2},
        "others": [
            {"walk": {"waypoints_m": [[12.09, 4.78], [20.0, -2.0]], "speed_mps": 1.2}}
        ],
        "double_reflections": false,
        "dt_s": 0.05
    })
}
