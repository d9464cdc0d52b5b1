//! Issue 39: the channel view's settings are the core's. The page reads the settings of the
//! core's `ChannelRequest` from its table (`study::channel_settings`, through wasm): every default
//! the page starts with is the table's (so a default re-typed in the page's JavaScript and then
//! changed in the core fails here), and every number setting is refused just outside the table's
//! range, by name, and accepted just inside.

use serde_json::{json, Value};

use scatterloc::study::{channel_settings, SettingKind};

use super::{console_errors, js, open_hash, with_browser};

/// The page's state key of a request key.
fn page_key(key: &str) -> &str {
    if key == "pfa" {
        "p_fa"
    } else {
        key
    }
}

/// The largest integer the page holds exactly (2^53 − 1).
const MAX_SAFE_INTEGER: f64 = 9_007_199_254_740_991.0;

#[test]
#[ignore = "needs chromium + chromedriver and www/pkg (wasm-pack build); run with --ignored"]
fn channel_defaults_and_ranges_are_the_cores() {
    let table = channel_settings();
    // [page key, value, whether the core's range takes it].
    let mut probes: Vec<(String, f64, bool)> = Vec::new();
    for s in &table {
        let key = page_key(s.key).to_string();
        let (b, integer) = match &s.kind {
            SettingKind::Number(b) => (b, false),
            SettingKind::Integer(b) => (b, true),
            SettingKind::Choice { .. } => continue,
        };
        let max = if integer {
            b.max.min(MAX_SAFE_INTEGER)
        } else {
            b.max
        };
        let (lo_in, lo_out) = match (integer, b.open[0]) {
            (true, _) => (b.min, b.min - 1.0),
            (false, true) => (f64::MIN_POSITIVE.max(b.min.next_up()), b.min),
            (false, false) => (b.min, b.min.next_down()),
        };
        let (hi_in, hi_out) = match (integer, b.open[1]) {
            (true, _) => (max, max + 1.0),
            (false, true) => (max.next_down(), max),
            (false, false) => (max, max.next_up()),
        };
        for (v, ok) in [
            (lo_in, true),
            (hi_in, true),
            (lo_out, false),
            (hi_out, false),
        ] {
            probes.push((key.clone(), v, ok));
        }
    }
    let probes_json = serde_json::to_string(
        &probes
            .iter()
            .map(|(k, v, _)| json!([k, v]))
            .collect::<Vec<_>>(),
    )
    .unwrap();
    let (defaults, answers, errors) = with_browser(async |c, port, _| {
        open_hash(c, port, "").await?;
        let defaults = js(c, "return window.channel.settings()").await?;
        let answers = js(
            c,
            &format!(
                "const base = window.channel.settings(); \
                 const out = {probes_json}.map(([k, v]) => {{ \
                   try {{ window.channel.applySettings({{ ...base, [k]: v }}); return null; }} \
                   catch (e) {{ return e.message; }} }}); \
                 window.channel.applySettings(base); return out;"
            ),
        )
        .await?;
        Ok((defaults, answers, console_errors(c).await?))
    });
    assert!(errors.is_empty(), "console errors: {errors:?}");
    for s in &table {
        let got = &defaults[page_key(s.key)];
        // No default: a choice shows `auto`, a number its lower end (cpi_snapshots: 1, off).
        let want = match (&s.kind, s.default.is_null()) {
            (SettingKind::Choice { .. }, true) => json!("auto"),
            (SettingKind::Number(b) | SettingKind::Integer(b), true) => json!(b.min),
            (_, false) => s.default.clone(),
        };
        let same = match (got.as_f64(), want.as_f64()) {
            (Some(a), Some(b)) => a == b,
            _ => *got == want,
        };
        assert!(same, "default of {}: page {got}, core {want}", s.key);
    }
    let answers = answers.as_array().expect("answers").clone();
    assert_eq!(answers.len(), probes.len());
    for ((key, v, ok), answer) in probes.iter().zip(answers) {
        match (ok, answer) {
            (true, Value::Null) => {}
            (false, Value::String(m)) => assert!(
                m.starts_with(&format!("channel setting {key}: ")) && m.contains("(allowed "),
                "{key} = {v:e}: {m}"
            ),
            (_, a) => panic!(
                "{key} = {v:e}: expected {}, got {a}",
                if *ok { "accepted" } else { "refused" }
            ),
        }
    }
}
