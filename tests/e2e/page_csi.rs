//! Issue 40 in the page: the channel view opens a Wi-Fi CSI file (here the ESP32 capture of
//! tests/data/csi, whose one antenna pair is link (Tx, Rx1) of the default scenario) through its
//! file input, the same reader as the CLI's (`csi::open_recording`): its summary is the CLI's
//! (snapshots, links, samples per link), Run finishes without an error, and a file of another
//! format the scenario cannot take (the Intel 5300 log: links (1, r) with one transmitter) is
//! named in the banner at open.

use fantoccini::Locator;
use serde_json::Value;

use super::ui::{banner, channel_state, wait_channel};
use super::{console_errors, js, open_hash, settle, with_browser};

fn data(name: &str) -> String {
    format!("{}/tests/data/csi/{name}", env!("CARGO_MANIFEST_DIR"))
}

#[test]
#[ignore = "needs chromium + chromedriver and www/pkg (wasm-pack build); run with --ignored"]
fn channel_view_opens_csi_files() {
    let esp = data("esp32/example_data.csv");
    let intel = data("intel/example.dat");
    // The CLI's view of the same file, with the page's defaults.
    let cli = std::process::Command::new(env!("CARGO_BIN_EXE_scatterloc"))
        .args([
            "cir",
            "convert",
            &esp,
            &std::env::temp_dir().join("page-csi.npz").to_string_lossy(),
        ])
        .output()
        .unwrap();
    assert!(cli.status.success());
    let want: Value = serde_json::from_slice(&cli.stdout).unwrap();
    let o = with_browser(async |c, port, _| {
        open_hash(c, port, "#mode=channel").await?;
        settle(c).await?;
        js(c, "document.getElementById('error-close').click()").await?;
        c.find(Locator::Id("chan-file"))
            .await
            .map_err(|e| e.to_string())?
            .send_keys(&esp)
            .await
            .map_err(|e| e.to_string())?;
        let opened = wait_channel(c, 60, "the ESP32 file opened", |s| {
            s["recording"]["name"] == "example_data.csv"
        })
        .await?;
        let after_open = banner(c).await?;
        js(c, "document.getElementById('chan-run').click()").await?;
        let done =
            wait_channel(c, 600, "run", |s| s["runs"] == 1 && s["running"].is_null()).await?;
        let after_run = banner(c).await?;
        c.find(Locator::Id("chan-file"))
            .await
            .map_err(|e| e.to_string())?
            .send_keys(&intel)
            .await
            .map_err(|e| e.to_string())?;
        let mut named = String::new();
        for _ in 0..200 {
            named = banner(c).await?;
            if !named.is_empty() {
                break;
            }
            tokio::time::sleep(std::time::Duration::from_millis(50)).await;
        }
        let state = channel_state(c).await?;
        Ok((
            opened,
            after_open,
            done,
            after_run,
            named,
            state,
            console_errors(c).await?,
        ))
    });
    let (opened, after_open, done, after_run, named, state, errors) = o;
    let rec = &opened["recording"];
    println!(
        "page: {rec}; CLI: frames {} grid {}",
        want["frames"], want["grid_bins"]
    );
    assert_eq!(rec["snapshots"], want["frames"]);
    assert_eq!(rec["links"], 1);
    assert_eq!(rec["layout"], "cfr");
    assert_eq!(rec["samples_per_link"], want["grid_bins"]);
    assert!(after_open.is_empty(), "{after_open}");
    assert!(done["error"].is_null(), "{}", done["error"]);
    assert!(after_run.is_empty(), "{after_run}");
    assert!(
        named.contains("links"),
        "the Intel log's links named: {named:?}"
    );
    assert_eq!(
        state["recording"]["name"], "example_data.csv",
        "the open one kept"
    );
    assert!(errors.is_empty(), "{errors:?}");
}
