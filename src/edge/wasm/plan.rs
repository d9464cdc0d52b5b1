//! The planner for the page's Plan panel (run in a Web Worker): a request as the CLI's flags, a
//! progress callback per generation, and `plan.json` as the result
//! ([`crate::present::run_plan`]).

use wasm_bindgen::prelude::*;

use super::err;
use super::json::to_js;
use crate::error::Error;
use crate::plan::MAX_PLAN_BUDGET;
use crate::present::{run_plan, PlanRequest, DEFAULT_PLAN_BUDGET};
use crate::Scenario;

/// The core's range of the Plan panel's budget, which the page range-checks before the core
/// does: `{"budget": [1, MAX_PLAN_BUDGET], "default_budget": DEFAULT_PLAN_BUDGET}`
/// ([`MAX_PLAN_BUDGET`], [`DEFAULT_PLAN_BUDGET`]), so the page and the core share one definition.
#[wasm_bindgen]
pub fn plan_field_ranges() -> String {
    serde_json::json!({
        "budget": [1, MAX_PLAN_BUDGET],
        "default_budget": DEFAULT_PLAN_BUDGET,
    })
    .to_string()
}

/// Plans a network on scenario JSON `scenario_json` (schema v1) for `request_json`:
/// `{move, objective, roi: [x0, x1, y0, y1], bounds?, allowed?, min_spacing_m?, grid?, budget?,
/// seed?}` (the CLI's `plan` flags). `on_progress(p)` is called after every generation with
/// `{evaluations, budget, improvement: null | {best, scenario}}`; returning `false` cancels
/// (the result is then a "cancelled" error). Returns `plan.json` as an object. Throws the core's
/// named error on bad input.
#[wasm_bindgen]
pub fn plan_network(
    scenario_json: &str,
    request_json: &str,
    on_progress: &js_sys::Function,
) -> Result<JsValue, JsError> {
    let scenario = Scenario::from_json(scenario_json).map_err(err)?;
    let request: PlanRequest = serde_json::from_str(request_json).map_err(|e| {
        err(Error::Parse {
            message: e.to_string(),
        })
    })?;
    let mut failed = None;
    let result = run_plan(&scenario, &request, |p| {
        let keep_going = to_js(p)
            .map_err(JsValue::from)
            .and_then(|v| on_progress.call1(&JsValue::NULL, &v));
        match keep_going {
            Ok(v) => v.as_bool() != Some(false),
            Err(e) => {
                failed = Some(e);
                false
            }
        }
    });
    if let Some(e) = failed {
        return Err(JsError::new(&format!(
            "plan: the progress callback failed: {}",
            e.as_string().unwrap_or_else(|| "an exception".into())
        )));
    }
    to_js(&result.map_err(err)?)
}
