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
