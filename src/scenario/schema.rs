//! Scenario JSON (schema v1): the network, the radio, the target and the area, with validation
//! that returns a named [`Error`] per problem. Positions are metres, SI everywhere else; dB only
//! where the field name says so.

use alloc::format;
use alloc::string::{String, ToString};
use alloc::vec::Vec;
use core::fmt;

use serde::de::{self, SeqAccess, Visitor};
use serde::{Deserialize, Deserializer, Serialize, Serializer};

use crate::error::{Error, Result};

mod validate;

#[cfg(test)]
mod tests;

/// A complete scenario: nodes, links, radio parameters, target and area of interest.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Scenario {
    /// Free-form name.
    pub name: String,
    /// Carrier, bandwidth and receiver noise.
    pub radio: Radio,
    /// Transmitters `r^Tx_k`, k = 1..K.
    pub transmitters: Vec<Transmitter>,
    /// Receivers `r^Rx_l`, l = 1..L.
    pub receivers: Vec<Receiver>,
    /// The link set 𝒫: `"all"` (k fastest, spec §1) or an explicit list of `[tx, rx]` names.
    #[serde(default)]
    pub links: LinkSpec,
    /// The scatterer's radar cross section.
    pub target: Target,
    /// Area of interest (default CRLB-map extent and LM grid-search area).
    pub area_m: Area,
}

/// Radio parameters (spec §7, §9.1).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Radio {
    /// Carrier frequency `f_c`, Hz.
    pub carrier_hz: f64,
    /// Bandwidth `B`, Hz (rectangular spectrum: `β = B/√12`).
    pub bandwidth_hz: f64,
    /// Receiver noise figure `F`, dB; noise power `P_n = k_B T₀ B F`. Default 10 dB.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub noise_figure_db: Option<f64>,
    /// Explicit noise power `P_n`, dBm (replaces `noise_figure_db`).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub noise_power_dbm: Option<f64>,
    /// Processing gain `B·T_p`, dB, added to every SNR (spec §7: an option, default 0).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub processing_gain_db: Option<f64>,
}

/// A transmitter.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Transmitter {
    /// Unique name.
    pub name: String,
    /// Position `r^Tx_k`, m.
    pub position_m: [f64; 2],
    /// Antenna height above the floor, m (default 0; omitted from the JSON when 0). With the
    /// target's [`Target::height_m`] it sets the node's vertical offset in the 3-D ranges (E1).
    #[serde(default, skip_serializing_if = "is_zero")]
    pub height_m: f64,
    /// Transmit power `P_Tx`, dBm.
    pub power_dbm: f64,
    /// Peak (boresight) antenna gain `G₀`, dBi.
    pub gain_dbi: f64,
    /// Antenna pattern (spec §9.3); omni when absent.
    #[serde(default)]
    pub pattern: Pattern,
}

/// Transmit antenna pattern (spec §9.3).
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize, Default)]
#[serde(tag = "kind", rename_all = "lowercase", deny_unknown_fields)]
pub enum Pattern {
    /// Same gain `G₀` in every direction (ψ_3dB = ∞).
    #[default]
    Omni,
    /// `G(ψ)[dBi] = G₀ − min(12 (ψ/ψ_3dB)², A_m)`.
    Parabolic {
        /// Boresight azimuth φ₀, degrees from +x toward +y.
        boresight_deg: f64,
        /// Half-power beamwidth ψ_3dB, degrees.
        beamwidth_deg: f64,
        /// Maximum attenuation A_m, dB.
        floor_db: f64,
    },
}

/// A receiver.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Receiver {
    /// Unique name.
    pub name: String,
    /// Position `r^Rx_l`, m.
    pub position_m: [f64; 2],
    /// Antenna height above the floor, m (default 0; omitted from the JSON when 0), as
    /// [`Transmitter::height_m`].
    #[serde(default, skip_serializing_if = "is_zero")]
    pub height_m: f64,
    /// Omnidirectional antenna gain `G_Rx`, dBi.
    pub gain_dbi: f64,
}

/// The scatterer.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Target {
    /// Radar cross section σ_RCS, m².
    pub rcs_m2: f64,
    /// Height of the horizontal plane the scatterer moves in (its body centre, e.g. 1.0 m for a
    /// walking person), m (default 0; omitted from the JSON when 0). Every position of the
    /// target is a point of this plane; ranges are 3-D from the nodes' heights (E1).
    #[serde(default, skip_serializing_if = "is_zero")]
    pub height_m: f64,
}

/// Whether a height is exactly 0 (the default, left out when serialising so that a planar
/// scenario's JSON is unchanged).
fn is_zero(v: &f64) -> bool {
    *v == 0.0
}

/// An axis-aligned rectangle, m.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Area {
    /// `[x_min, x_max]`.
    pub x: [f64; 2],
    /// `[y_min, y_max]`.
    pub y: [f64; 2],
}

/// The link set of a scenario.
#[derive(Debug, Clone, PartialEq, Default)]
pub enum LinkSpec {
    /// Full mesh, canonical order k fastest: (1,1), (2,1), …, (K,1), (1,2), …, (K,L) (spec §1).
    #[default]
    All,
    /// Explicit `[tx, rx]` name pairs; this list's order is the link order.
    List(Vec<[String; 2]>),
}

impl Serialize for LinkSpec {
    fn serialize<S: Serializer>(&self, s: S) -> core::result::Result<S::Ok, S::Error> {
        match self {
            LinkSpec::All => s.serialize_str("all"),
            LinkSpec::List(v) => v.serialize(s),
        }
    }
}

impl<'de> Deserialize<'de> for LinkSpec {
    fn deserialize<D: Deserializer<'de>>(d: D) -> core::result::Result<Self, D::Error> {
        struct V;
        impl<'de> Visitor<'de> for V {
            type Value = LinkSpec;
            fn expecting(&self, f: &mut fmt::Formatter) -> fmt::Result {
                f.write_str("\"all\" or a list of [\"TxName\", \"RxName\"] pairs")
            }
            fn visit_str<E: de::Error>(self, v: &str) -> core::result::Result<LinkSpec, E> {
                if v == "all" {
                    Ok(LinkSpec::All)
                } else {
                    Err(E::invalid_value(de::Unexpected::Str(v), &self))
                }
            }
            fn visit_seq<A: SeqAccess<'de>>(
                self,
                mut seq: A,
            ) -> core::result::Result<LinkSpec, A::Error> {
                let mut out = Vec::new();
                while let Some(pair) = seq.next_element::<[String; 2]>()? {
                    out.push(pair);
                }
                Ok(LinkSpec::List(out))
            }
        }
        d.deserialize_any(V)
    }
}

/// Index pair of a link: transmitter `k` and receiver `l` (0-based).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct LinkIndex {
    /// Transmitter index k.
    pub tx: usize,
    /// Receiver index l.
    pub rx: usize,
}

impl Scenario {
    /// Parses and validates scenario JSON.
    pub fn from_json(text: &str) -> Result<Scenario> {
        let s: Scenario = parse_json(text)?;
        s.validate()?;
        Ok(s)
    }

    /// Pretty JSON of this scenario (same schema as [`Scenario::from_json`] reads).
    pub fn to_json(&self) -> String {
        // Serialising plain data with finite numbers cannot fail.
        serde_json::to_string_pretty(self).unwrap_or_default()
    }

    /// The link set as index pairs, in link order (validated names).
    pub fn link_indices(&self) -> Result<Vec<LinkIndex>> {
        match &self.links {
            LinkSpec::All => {
                let (k, l) = (self.transmitters.len(), self.receivers.len());
                Ok((0..l)
                    .flat_map(|rx| (0..k).map(move |tx| LinkIndex { tx, rx }))
                    .collect())
            }
            LinkSpec::List(pairs) => {
                if pairs.is_empty() {
                    return Err(Error::EmptyLinkList);
                }
                let mut out: Vec<LinkIndex> = Vec::with_capacity(pairs.len());
                for (i, [t, r]) in pairs.iter().enumerate() {
                    let tx = self
                        .transmitters
                        .iter()
                        .position(|n| &n.name == t)
                        .ok_or_else(|| Error::UnknownNode {
                            field: format!("links[{i}][0]"),
                            name: t.clone(),
                        })?;
                    let rx = self
                        .receivers
                        .iter()
                        .position(|n| &n.name == r)
                        .ok_or_else(|| Error::UnknownNode {
                            field: format!("links[{i}][1]"),
                            name: r.clone(),
                        })?;
                    let li = LinkIndex { tx, rx };
                    if out.contains(&li) {
                        return Err(Error::DuplicateLink {
                            tx: t.clone(),
                            rx: r.clone(),
                        });
                    }
                    out.push(li);
                }
                Ok(out)
            }
        }
    }

    /// Human-readable link labels `(tx name, rx name)` in link order.
    pub fn link_names(&self) -> Result<Vec<(String, String)>> {
        Ok(self
            .link_indices()?
            .iter()
            .map(|l| {
                (
                    self.transmitters[l.tx].name.clone(),
                    self.receivers[l.rx].name.clone(),
                )
            })
            .collect())
    }
}

/// Deserializes JSON, naming the path of the offending field in the error (e.g.
/// `radio.bandwidth_hz: invalid type: string "120e6", expected f64 at line 5 column 27`).
pub fn parse_json<T: serde::de::DeserializeOwned>(text: &str) -> Result<T> {
    let mut de = serde_json::Deserializer::from_str(text);
    let value: T = serde_path_to_error::deserialize(&mut de).map_err(|e| {
        let path = e.path().to_string();
        let inner = e.into_inner();
        let message = if path.is_empty() || path == "." {
            inner.to_string()
        } else {
            format!("{path}: {inner}")
        };
        Error::Parse { message }
    })?;
    de.end().map_err(|e| Error::Parse {
        message: e.to_string(),
    })?;
    Ok(value)
}
