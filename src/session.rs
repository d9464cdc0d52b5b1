//! The state of an interactive front end: a validated [`Scenario`] and its compiled [`Model`],
//! kept in step. Edits (the [`crate::edit`] methods, or any closure) run on a copy that must
//! validate and compile before it replaces both, so a rejected edit changes nothing.

use crate::error::Result;
use crate::model::Model;
use crate::scenario::Scenario;

/// A validated scenario and the model compiled from it.
#[derive(Debug, Clone, PartialEq)]
pub struct Session {
    scenario: Scenario,
    model: Model,
}

impl Session {
    /// Validates and compiles `scenario`.
    pub fn new(scenario: Scenario) -> Result<Session> {
        let model = Model::new(&scenario)?;
        Ok(Session { scenario, model })
    }

    /// The scenario.
    pub fn scenario(&self) -> &Scenario {
        &self.scenario
    }

    /// The model compiled from [`Session::scenario`].
    pub fn model(&self) -> &Model {
        &self.model
    }

    /// Applies `f` to a copy of the scenario; commits it and its recompiled model only if `f`
    /// succeeds and the result compiles. Returns `f`'s result.
    pub fn edit<T>(&mut self, f: impl FnOnce(&mut Scenario) -> Result<T>) -> Result<T> {
        let (out, model) = self.scenario.apply_checked(f, Model::new)?;
        self.model = model;
        Ok(out)
    }

    /// Replaces the scenario (validated and compiled first).
    pub fn replace(&mut self, scenario: Scenario) -> Result<()> {
        *self = Session::new(scenario)?;
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::error::Error;
    use crate::presets::{iclgnss2019, sensors2019};

    #[test]
    fn edits_recompile_the_model_and_rejected_ones_change_nothing() {
        let mut s = Session::new(sensors2019()).unwrap();
        assert_eq!(s.edit(|sc| sc.add_receiver([3.0, 4.0])), Ok(4));
        assert_eq!(s.model().link_count(), 5);
        assert_eq!(s.model(), &Model::new(s.scenario()).unwrap());
        let before = s.clone();
        assert!(matches!(
            s.edit(|sc| sc.set_bandwidth_hz(0.0)),
            Err(Error::NotPositive { .. })
        ));
        assert!(s.edit(|sc| sc.remove_transmitter(0)).is_err());
        let mut bad = iclgnss2019();
        bad.target.rcs_m2 = -1.0;
        assert!(s.replace(bad).is_err());
        assert_eq!(s, before);
        s.replace(iclgnss2019()).unwrap();
        assert_eq!(s.model().link_count(), 3);
    }
}
