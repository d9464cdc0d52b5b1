//! Takes a docs screenshot of the page through the browser harness of the end-to-end tests
//! (tests/e2e.rs, tests/e2e/screenshot.rs): docs/screenshot-tracking.png by default.
//!
//! ```sh
//! wasm-pack build --release --target web --out-dir www/pkg --mode no-install
//! CHROMEDRIVER=/usr/bin/chromedriver cargo run --example screenshot
//! # another view, file and size:
//! SCATTERLOC_SCREENSHOT_HASH='#mode=mtl' SCATTERLOC_SCREENSHOT_OUT=docs/screenshot-mtl.png \
//!   cargo run --example screenshot
//! ```
//!
//! A helper, not a test: it asserts nothing, so it is not counted among the tests.

#[allow(dead_code, unused_imports)]
#[path = "../tests/e2e.rs"]
mod e2e;

fn main() {
    // tests/e2e.rs is native only (chromedriver, a local server).
    #[cfg(not(target_arch = "wasm32"))]
    e2e::screenshot::tracking_screenshot();
}
