//! Scenario editing for interactive front ends (the page's panel and drag handles): add, remove
//! and move nodes, set radio, target and antenna parameters. Every edit runs on a copy that is
//! validated before it replaces the scenario, so a rejected edit leaves it bit-identical and
//! returns a named [`Error`]. Nodes get fresh unique names (`Tx1`, `Rx5`, …); with an explicit
//! link list (spec §1: the link set 𝒫) a new node is linked to every node on the other side and a
//! removed node takes its links along.

use alloc::format;
use alloc::string::String;

use crate::error::{checked_index, Error, Result};
use crate::scenario::{Area, LinkSpec, Pattern, Receiver, Scenario, Transmitter};

impl Scenario {
    /// Applies `f` to a copy, then `check`s the copy; commits only if both succeed and returns
    /// both results. On error `self` is untouched.
    pub fn apply_checked<T, C>(
        &mut self,
        f: impl FnOnce(&mut Scenario) -> Result<T>,
        check: impl FnOnce(&Scenario) -> Result<C>,
    ) -> Result<(T, C)> {
        let mut copy = self.clone();
        let out = f(&mut copy)?;
        let checked = check(&copy)?;
        *self = copy;
        Ok((out, checked))
    }

    /// Applies `f` to a copy and commits it only if it [validates](Scenario::validate).
    pub fn apply<T>(&mut self, f: impl FnOnce(&mut Scenario) -> Result<T>) -> Result<T> {
        self.apply_checked(f, Scenario::validate)
            .map(|(out, ())| out)
    }

    /// The first name `prefix1`, `prefix2`, … not used by any node.
    pub fn fresh_name(&self, prefix: &str) -> String {
        let taken = |n: &str| {
            self.transmitters.iter().any(|t| t.name == n)
                || self.receivers.iter().any(|r| r.name == n)
        };
        (1..)
            .map(|i| format!("{prefix}{i}"))
            .find(|n| !taken(n))
            .unwrap_or_default()
    }

    /// `i` if transmitter `i` exists, else [`Error::IndexOutOfRange`].
    pub fn transmitter_index(&self, i: usize) -> Result<usize> {
        checked_index("transmitters", i, self.transmitters.len())
    }

    /// `i` if receiver `i` exists, else [`Error::IndexOutOfRange`].
    pub fn receiver_index(&self, i: usize) -> Result<usize> {
        checked_index("receivers", i, self.receivers.len())
    }

    /// Adds a transmitter at `position_m` with the radio settings and height of the last one and a fresh
    /// name (`TxN`); with an explicit link list it is linked to every receiver. Returns its index.
    pub fn add_transmitter(&mut self, position_m: [f64; 2]) -> Result<usize> {
        self.apply(|s| {
            let mut t = s.transmitters.last().cloned().ok_or(Error::EmptyNodeList {
                field: "transmitters",
            })?;
            t.name = s.fresh_name("Tx");
            t.position_m = position_m;
            if let LinkSpec::List(l) = &mut s.links {
                l.extend(s.receivers.iter().map(|r| [t.name.clone(), r.name.clone()]));
            }
            s.transmitters.push(t);
            Ok(s.transmitters.len() - 1)
        })
    }

    /// Adds a receiver at `position_m` with the gain and height of the last one and a fresh name (`RxN`);
    /// with an explicit link list it is linked to every transmitter. Returns its index.
    pub fn add_receiver(&mut self, position_m: [f64; 2]) -> Result<usize> {
        self.apply(|s| {
            let r = Receiver {
                name: s.fresh_name("Rx"),
                position_m,
                height_m: s.receivers.last().map_or(0.0, |r| r.height_m),
                gain_dbi: s.receivers.last().map_or(0.0, |r| r.gain_dbi),
            };
            if let LinkSpec::List(l) = &mut s.links {
                l.extend(
                    s.transmitters
                        .iter()
                        .map(|t| [t.name.clone(), r.name.clone()]),
                );
            }
            s.receivers.push(r);
            Ok(s.receivers.len() - 1)
        })
    }

    /// Removes transmitter `i` and its links; the last one cannot be removed
    /// ([`Error::LastNode`]).
    pub fn remove_transmitter(&mut self, i: usize) -> Result<()> {
        self.apply(|s| {
            let i = s.transmitter_index(i)?;
            if s.transmitters.len() == 1 {
                return Err(Error::LastNode {
                    field: "transmitters",
                });
            }
            let t = s.transmitters.remove(i);
            if let LinkSpec::List(l) = &mut s.links {
                l.retain(|p| p[0] != t.name);
            }
            Ok(())
        })
    }

    /// Removes receiver `i` and its links; the last one cannot be removed ([`Error::LastNode`]).
    pub fn remove_receiver(&mut self, i: usize) -> Result<()> {
        self.apply(|s| {
            let i = s.receiver_index(i)?;
            if s.receivers.len() == 1 {
                return Err(Error::LastNode { field: "receivers" });
            }
            let r = s.receivers.remove(i);
            if let LinkSpec::List(l) = &mut s.links {
                l.retain(|p| p[1] != r.name);
            }
            Ok(())
        })
    }

    /// Moves transmitter `i` to `position_m`, m.
    pub fn move_transmitter(&mut self, i: usize, position_m: [f64; 2]) -> Result<()> {
        self.edit_transmitter(i, |t| t.position_m = position_m)
    }

    /// Moves receiver `i` to `position_m`, m.
    pub fn move_receiver(&mut self, i: usize, position_m: [f64; 2]) -> Result<()> {
        self.edit_receiver(i, |r| r.position_m = position_m)
    }

    /// Sets the area of interest.
    pub fn set_area(&mut self, area: Area) -> Result<()> {
        self.edit_with(|s| s.area_m = area)
    }

    /// Sets the carrier frequency `f_c`, Hz.
    pub fn set_carrier_hz(&mut self, v: f64) -> Result<()> {
        self.edit_with(|s| s.radio.carrier_hz = v)
    }

    /// Sets the bandwidth `B`, Hz.
    pub fn set_bandwidth_hz(&mut self, v: f64) -> Result<()> {
        self.edit_with(|s| s.radio.bandwidth_hz = v)
    }

    /// Sets the receiver noise figure `F`, dB; an explicit noise power is dropped (the two are
    /// exclusive, spec §7).
    pub fn set_noise_figure_db(&mut self, v: f64) -> Result<()> {
        self.edit_with(|s| {
            s.radio.noise_figure_db = Some(v);
            s.radio.noise_power_dbm = None;
        })
    }

    /// Sets the target radar cross section σ_RCS, m².
    pub fn set_rcs_m2(&mut self, v: f64) -> Result<()> {
        self.edit_with(|s| s.target.rcs_m2 = v)
    }

    /// Sets the transmit power `P_Tx` of transmitter `i`, dBm.
    pub fn set_tx_power_dbm(&mut self, i: usize, v: f64) -> Result<()> {
        self.edit_transmitter(i, |t| t.power_dbm = v)
    }

    /// Sets the peak antenna gain `G₀` of transmitter `i`, dBi.
    pub fn set_tx_gain_dbi(&mut self, i: usize, v: f64) -> Result<()> {
        self.edit_transmitter(i, |t| t.gain_dbi = v)
    }

    /// Sets the antenna pattern of transmitter `i` (spec §9.3).
    pub fn set_tx_pattern(&mut self, i: usize, pattern: Pattern) -> Result<()> {
        self.edit_transmitter(i, |t| t.pattern = pattern)
    }

    /// Sets the antenna pattern of transmitter `i` by kind name: `"omni"` (the angles are
    /// ignored) or `"parabolic"` with boresight azimuth φ₀ and half-power beamwidth ψ_3dB
    /// (degrees) and floor A_m (dB). An unknown kind is [`Error::UnknownPattern`].
    pub fn set_tx_pattern_kind(
        &mut self,
        i: usize,
        kind: &str,
        boresight_deg: f64,
        beamwidth_deg: f64,
        floor_db: f64,
    ) -> Result<()> {
        let i = self.transmitter_index(i)?;
        let pattern = match kind {
            "omni" => Pattern::Omni,
            "parabolic" => Pattern::Parabolic {
                boresight_deg,
                beamwidth_deg,
                floor_db,
            },
            _ => {
                return Err(Error::UnknownPattern {
                    field: format!("transmitters[{i}].pattern.kind"),
                    kind: kind.into(),
                })
            }
        };
        self.set_tx_pattern(i, pattern)
    }

    /// Sets the antenna gain `G_Rx` of receiver `i`, dBi.
    pub fn set_rx_gain_dbi(&mut self, i: usize, v: f64) -> Result<()> {
        self.edit_receiver(i, |r| r.gain_dbi = v)
    }

    /// Sets the antenna height of transmitter `i`, m (issue 40; validated as
    /// `transmitters[i].height_m`).
    pub fn set_tx_height_m(&mut self, i: usize, v: f64) -> Result<()> {
        self.edit_transmitter(i, |t| t.height_m = v)
    }

    /// Sets the antenna height of receiver `i`, m (validated as `receivers[i].height_m`).
    pub fn set_rx_height_m(&mut self, i: usize, v: f64) -> Result<()> {
        self.edit_receiver(i, |r| r.height_m = v)
    }

    /// Sets the height of the target's plane (its body centre), m (`target.height_m`).
    pub fn set_target_height_m(&mut self, v: f64) -> Result<()> {
        self.edit_with(|s| s.target.height_m = v)
    }

    /// [`Scenario::apply`] of an infallible change.
    fn edit_with(&mut self, f: impl FnOnce(&mut Scenario)) -> Result<()> {
        self.apply(|s| {
            f(s);
            Ok(())
        })
    }

    /// [`Scenario::apply`] of a change to transmitter `i` (which must exist).
    fn edit_transmitter(&mut self, i: usize, f: impl FnOnce(&mut Transmitter)) -> Result<()> {
        self.apply(|s| {
            let i = s.transmitter_index(i)?;
            f(&mut s.transmitters[i]);
            Ok(())
        })
    }

    /// [`Scenario::apply`] of a change to receiver `i` (which must exist).
    fn edit_receiver(&mut self, i: usize, f: impl FnOnce(&mut Receiver)) -> Result<()> {
        self.apply(|s| {
            let i = s.receiver_index(i)?;
            f(&mut s.receivers[i]);
            Ok(())
        })
    }
}

#[cfg(test)]
mod tests;
