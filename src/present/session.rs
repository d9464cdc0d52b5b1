//! The state of an interactive front end: a validated [`Scenario`] and its compiled [`Model`],
//! kept in step. Edits (the [`crate::scenario`] methods, or any closure) run on a copy that must
//! validate and compile before it replaces both, so a rejected edit changes nothing.

use crate::error::Result;
use crate::measure::Model;
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
    /// Unchanged transmitter patterns are not refitted ([`Model::recompile`]).
    pub fn edit<T>(&mut self, f: impl FnOnce(&mut Scenario) -> Result<T>) -> Result<T> {
        let mut copy = self.scenario.clone();
        let out = f(&mut copy)?;
        let model = self.model.recompile(&self.scenario, &copy)?;
        self.scenario = copy;
        self.model = model;
        Ok(out)
    }

    /// Replaces the scenario (validated and compiled first; patterns it shares with the current
    /// one are not refitted, [`Model::recompile`]).
    pub fn replace(&mut self, scenario: Scenario) -> Result<()> {
        self.model = self.model.recompile(&self.scenario, &scenario)?;
        self.scenario = scenario;
        Ok(())
    }
}

#[cfg(test)]
mod tests;
