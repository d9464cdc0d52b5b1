//! SVG checks of the figure-export tests (`tests/wasm/export.rs`, `tests/e2e/export.rs`): the
//! texts of a document's `<text>` elements, and how often one occurs. Included by path (the wasm
//! tests cannot compile the rest of `common`, which runs processes).

/// The texts of the `<text>` elements of `svg`, which must parse as an SVG document (`what`
/// names it in a failure).
pub fn svg_texts(what: &str, svg: &str) -> Vec<String> {
    let doc = roxmltree::Document::parse(svg)
        .unwrap_or_else(|e| panic!("{what}: the SVG does not parse as XML: {e}"));
    assert_eq!(doc.root_element().tag_name().name(), "svg", "{what}");
    doc.descendants()
        .filter(|n| n.has_tag_name("text"))
        .map(|n| n.text().unwrap_or("").trim().to_string())
        .collect()
}

/// How many of `texts` equal `s`.
pub fn count(texts: &[String], s: &str) -> usize {
    texts.iter().filter(|t| t.as_str() == s).count()
}

/// The PNG bytes of the one `<image>` of `svg` (a map figure: its map embedded as a
/// `data:image/png;base64,…` URI), checked to be the only image and to start with the PNG
/// signature (`what` names it in a failure).
#[allow(dead_code)]
pub fn embedded_png(what: &str, svg: &str) -> Vec<u8> {
    let doc = roxmltree::Document::parse(svg)
        .unwrap_or_else(|e| panic!("{what}: the SVG does not parse as XML: {e}"));
    let images: Vec<_> = doc
        .descendants()
        .filter(|n| n.has_tag_name("image"))
        .collect();
    assert_eq!(images.len(), 1, "{what}: one embedded image");
    let href = images[0].attribute("href").unwrap_or("");
    let b64 = href
        .strip_prefix("data:image/png;base64,")
        .unwrap_or_else(|| {
            panic!(
                "{what}: not a PNG data URI: {}",
                &href[..href.len().min(40)]
            )
        });
    let val = |c: u8| -> u32 {
        match c {
            b'A'..=b'Z' => u32::from(c - b'A'),
            b'a'..=b'z' => u32::from(c - b'a') + 26,
            b'0'..=b'9' => u32::from(c - b'0') + 52,
            b'+' => 62,
            b'/' => 63,
            b'=' => 0,
            _ => panic!("{what}: not base64: {c}"),
        }
    };
    let mut out = Vec::with_capacity(b64.len() / 4 * 3);
    for q in b64.as_bytes().chunks(4) {
        let pad = q.iter().filter(|&&c| c == b'=').count();
        let n = q.iter().fold(0u32, |a, &c| (a << 6) | val(c));
        out.extend_from_slice(&[(n >> 16) as u8, (n >> 8) as u8, n as u8][..3 - pad]);
    }
    assert_eq!(
        &out[..8],
        &[0x89, b'P', b'N', b'G', b'\r', b'\n', 0x1a, b'\n'],
        "{what}: PNG signature"
    );
    out
}
