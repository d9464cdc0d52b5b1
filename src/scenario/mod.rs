//! The scenario: what a user describes. Schema v1 of the scenario JSON (network, radio, target,
//! area; positions in metres, SI elsewhere, dB only where the name says so) with validation that
//! names the offending field ([`Scenario::validate`]), the case studies of spec §9 ([`presets`]),
//! and validated, rolled-back editing for interactive front ends ([`Scenario`]'s edit methods).
//! Everything downstream starts from a validated [`Scenario`].

mod edit;
pub mod presets;
mod schema;

pub use schema::{
    parse_json, Area, LinkIndex, LinkSpec, Pattern, Radio, Receiver, Scenario, Target, Transmitter,
};
