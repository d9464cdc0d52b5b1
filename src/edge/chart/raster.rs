//! The CRLB map of a vector (SVG) figure as ONE embedded image: the map's cells coloured on the
//! figure's scale, encoded as an RGB PNG at the grid's resolution (one pixel per cell, row 0 the
//! top = highest y) and placed as an `<image>` with a `data:image/png;base64,…` URI under the
//! figure's vector layers (axes, overlays, nodes, colour bar and text). Pure Rust (zlib and CRC-32
//! of flate2's miniz_oxide backend), so the page's wasm build and the CLI share it.

use alloc::string::String;
use alloc::vec::Vec;

use std::io::Write;

use super::panel::MapData;
use crate::present::{LogScale, UNBOUNDED_RGB};

/// The 8 bytes every PNG file starts with.
pub const PNG_SIGNATURE: [u8; 8] = [0x89, b'P', b'N', b'G', b'\r', b'\n', 0x1a, b'\n'];

/// The prefix of the embedded map's `href`.
pub const PNG_DATA_URI: &str = "data:image/png;base64,";

/// The RGB colours of the map's cells on `scale` (grey where unbounded or without a scale), in
/// image order: rows from the highest y down, `nx` pixels each.
pub fn map_rgb(map: &MapData, scale: Option<&LogScale>) -> Vec<u8> {
    let (nx, ny) = (map.grid.nx, map.grid.ny);
    let mut rgb = Vec::with_capacity(3 * nx * ny);
    for j in (0..ny).rev() {
        for &v in &map.values_m[j * nx..(j + 1) * nx] {
            let c = match scale {
                Some(s) => s.color(v),
                None => UNBOUNDED_RGB,
            };
            rgb.extend_from_slice(&c);
        }
    }
    rgb
}

/// One PNG chunk: length, type, data, CRC-32 of type and data.
fn chunk(out: &mut Vec<u8>, kind: &[u8; 4], data: &[u8]) {
    out.extend_from_slice(&(data.len() as u32).to_be_bytes());
    out.extend_from_slice(kind);
    out.extend_from_slice(data);
    let mut crc = flate2::Crc::new();
    crc.update(kind);
    crc.update(data);
    out.extend_from_slice(&crc.sum().to_be_bytes());
}

/// An 8-bit RGB PNG of `width × height` pixels from `rgb` (3 bytes per pixel, rows top down; no
/// row filter, zlib-deflated). `None` if the sizes do not match or are zero.
pub fn encode_png(width: usize, height: usize, rgb: &[u8]) -> Option<Vec<u8>> {
    if width == 0 || height == 0 || rgb.len() != 3 * width * height {
        return None;
    }
    let (w, h) = (u32::try_from(width).ok()?, u32::try_from(height).ok()?);
    let mut raw = Vec::with_capacity(height * (1 + 3 * width));
    for row in rgb.chunks_exact(3 * width) {
        raw.push(0); // filter type: none
        raw.extend_from_slice(row);
    }
    let mut z = flate2::write::ZlibEncoder::new(Vec::new(), flate2::Compression::default());
    z.write_all(&raw).ok()?;
    let idat = z.finish().ok()?;
    let mut out = Vec::with_capacity(idat.len() + 64);
    out.extend_from_slice(&PNG_SIGNATURE);
    let mut ihdr = Vec::with_capacity(13);
    ihdr.extend_from_slice(&w.to_be_bytes());
    ihdr.extend_from_slice(&h.to_be_bytes());
    ihdr.extend_from_slice(&[8, 2, 0, 0, 0]); // 8 bits, RGB, deflate, no filter, no interlace
    chunk(&mut out, b"IHDR", &ihdr);
    chunk(&mut out, b"IDAT", &idat);
    chunk(&mut out, b"IEND", &[]);
    Some(out)
}

/// Standard base64 (RFC 4648, with padding) of `bytes`.
pub fn base64(bytes: &[u8]) -> String {
    const A: &[u8; 64] = b"ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
    let mut s = String::with_capacity(bytes.len().div_ceil(3) * 4);
    for c in bytes.chunks(3) {
        let n = (u32::from(c[0]) << 16)
            | (u32::from(*c.get(1).unwrap_or(&0)) << 8)
            | u32::from(*c.get(2).unwrap_or(&0));
        for k in 0..4 {
            if k <= c.len() {
                s.push(A[(n >> (18 - 6 * k)) as usize & 63] as char);
            } else {
                s.push('=');
            }
        }
    }
    s
}

/// The pixel rectangle `(x, y, width, height)` of a figure's plot, which the image fills.
pub type PlotPixels = (i32, i32, i32, i32);

/// Inserts the map's PNG as one `<image>` filling `plot` into `svg` (plotters' SVG text), right
/// after the figure's white background (its first element), so every vector layer stays on top.
/// `None` if the SVG has no first element to insert after.
pub fn embed_png(svg: &str, plot: PlotPixels, png: &[u8]) -> Option<String> {
    embed_pngs(svg, &[(plot, png.to_vec())])
}

/// [`embed_png`] for several images (the delay figure's panels), in order.
pub fn embed_pngs(svg: &str, images: &[(PlotPixels, Vec<u8>)]) -> Option<String> {
    let open = svg.find("<svg")?;
    let first = open + svg[open..].find('>')? + 1;
    let first_el = first + svg[first..].find('<')?;
    let after = first_el + svg[first_el..].find("/>")? + 2;
    let mut out =
        String::with_capacity(svg.len() + images.iter().map(|i| i.1.len() * 2).sum::<usize>());
    out.push_str(&svg[..after]);
    for ((x, y, w, h), png) in images {
        out.push_str(&alloc::format!(
            "\n<image x=\"{x}\" y=\"{y}\" width=\"{w}\" height=\"{h}\" \
             preserveAspectRatio=\"none\" style=\"image-rendering:pixelated\" \
             href=\"{PNG_DATA_URI}{}\"/>",
            base64(png)
        ));
    }
    out.push_str(&svg[after..]);
    Some(out)
}

#[cfg(test)]
mod tests {
    use super::{base64, encode_png};

    /// RFC 4648 §10's test vectors.
    #[test]
    fn base64_of_the_rfc_vectors() {
        for (i, o) in [
            ("", ""),
            ("f", "Zg=="),
            ("fo", "Zm8="),
            ("foo", "Zm9v"),
            ("foob", "Zm9vYg=="),
            ("fooba", "Zm9vYmE="),
            ("foobar", "Zm9vYmFy"),
        ] {
            assert_eq!(base64(i.as_bytes()), o);
        }
    }

    /// The PNG decodes (the `image` crate of the CLI, natively) to the same pixels; bad sizes
    /// are refused.
    #[cfg(all(not(target_arch = "wasm32"), feature = "cli"))]
    #[test]
    fn png_round_trips_through_a_decoder() {
        let (w, h) = (7, 3);
        let rgb: Vec<u8> = (0..3 * w * h).map(|k| (k * 37 % 251) as u8).collect();
        let png = encode_png(w, h, &rgb).unwrap();
        let img = image::load_from_memory_with_format(&png, image::ImageFormat::Png)
            .unwrap()
            .to_rgb8();
        assert_eq!((img.width(), img.height()), (w as u32, h as u32));
        assert_eq!(img.into_raw(), rgb);
        assert!(encode_png(0, 3, &[]).is_none());
        assert!(encode_png(2, 2, &[0; 11]).is_none());
    }

    /// The sensors2019 map at 256² as SVG: before (one rectangle per run of equal colour) and
    /// after (one embedded PNG); the PNG decodes to the colour of every cell on the figure's
    /// scale, and the vector layers (the colour bar's labels, the nodes) are still text.
    #[cfg(all(not(target_arch = "wasm32"), feature = "cli"))]
    #[test]
    fn map_svg_embeds_one_png_of_the_cells() {
        use crate::chart::{crlb_map_svg, draw_crlb_map, scenario_nodes, ChartOptions, MapData};
        use crate::chart::{MapOverlay, PNG_DATA_URI};
        use crate::localize::{crlb_map, Grid};
        use crate::present::LogScale;
        use crate::{scenario::presets, Model};
        use plotters::prelude::*;

        let s = presets::sensors2019();
        let model = Model::new(&s).unwrap();
        let grid = Grid::new(s.area_m, 256, 256).unwrap();
        let mut v = vec![0.0; grid.len()];
        crlb_map(&model, &grid, &mut v).unwrap();
        let map = MapData { grid, values_m: &v };
        let nodes = scenario_nodes(&s);
        let opts = ChartOptions::default();
        let size = crate::chart::suggested_size(&s.area_m, 1000);
        let mut old = String::new();
        {
            let root = SVGBackend::with_string(&mut old, size).into_drawing_area();
            draw_crlb_map(&root, &map, &nodes, &opts).unwrap();
            root.present().unwrap();
        }
        let (new, summary) =
            crlb_map_svg(size, &map, &nodes, &MapOverlay::default(), &opts).unwrap();
        let doc = roxmltree::Document::parse(&new).unwrap();
        let rects =
            |d: &roxmltree::Document| d.descendants().filter(|n| n.has_tag_name("rect")).count();
        let old_doc = roxmltree::Document::parse(&old).unwrap();
        println!(
            "map SVG 256²: before {} bytes ({} rect), after {} bytes ({} rect, 1 image)",
            old.len(),
            rects(&old_doc),
            new.len(),
            rects(&doc)
        );
        assert!(new.len() * 5 < old.len(), "{} vs {}", new.len(), old.len());
        let images: Vec<_> = doc
            .descendants()
            .filter(|n| n.has_tag_name("image"))
            .collect();
        assert_eq!(images.len(), 1);
        // The image is the first element after the white background: under every vector layer.
        let first: Vec<_> = doc
            .root_element()
            .children()
            .filter(|n| n.is_element())
            .take(2)
            .collect();
        assert!(first[0].has_tag_name("rect") && first[1].has_tag_name("image"));
        let b64 = images[0]
            .attribute("href")
            .unwrap()
            .strip_prefix(PNG_DATA_URI)
            .unwrap();
        let png = decode(b64);
        let img = image::load_from_memory_with_format(&png, image::ImageFormat::Png)
            .unwrap()
            .to_rgb8();
        assert_eq!((img.width(), img.height()), (256, 256));
        let scale = LogScale::spanning(&v).unwrap();
        assert_eq!(summary.scale, Some(scale));
        for j in 0..256 {
            for i in 0..256 {
                let p = img.get_pixel(i as u32, 255 - j as u32).0;
                assert_eq!(p, scale.color(v[j * 256 + i]), "cell ({i}, {j})");
            }
        }
        let texts: Vec<&str> = doc
            .descendants()
            .filter(|n| n.has_tag_name("text"))
            .filter_map(|n| n.text())
            .collect();
        for n in ["Tx", "Rx1", "Rx4", "x (m)", "RMSE bound √(σx² + σy²)"] {
            assert!(texts.iter().any(|t| t.trim() == n), "{n} in {texts:?}");
        }
    }

    /// A locked scale narrower than the map: the cells outside it in the end colours and the
    /// colour bar marked `≤ min` and `≥ max`.
    #[cfg(all(not(target_arch = "wasm32"), feature = "cli"))]
    #[test]
    fn locked_scale_marks_both_ends() {
        use crate::chart::{crlb_map_svg, scenario_nodes, ChartOptions, MapData, MapOverlay};
        use crate::localize::{crlb_map, Grid};
        use crate::present::{format_length_m, LogScale};
        use crate::{scenario::presets, Model};
        let s = presets::sensors2019();
        let model = Model::new(&s).unwrap();
        let grid = Grid::new(s.area_m, 64, 64).unwrap();
        let mut v = vec![0.0; grid.len()];
        crlb_map(&model, &grid, &mut v).unwrap();
        let auto = LogScale::spanning(&v).unwrap();
        let locked = LogScale::new(auto.min * 3.0, auto.max / 3.0).unwrap();
        let [below, above] = locked.clamped_counts(&v);
        assert!(below > 0 && above > 0);
        let opts = ChartOptions {
            scale: Some(locked),
            ..ChartOptions::default()
        };
        let map = MapData { grid, values_m: &v };
        let (svg, summary) = crlb_map_svg(
            (900, 800),
            &map,
            &scenario_nodes(&s),
            &MapOverlay::default(),
            &opts,
        )
        .unwrap();
        assert_eq!(summary.scale, Some(locked));
        let doc = roxmltree::Document::parse(&svg).unwrap();
        let texts: Vec<&str> = doc
            .descendants()
            .filter(|n| n.has_tag_name("text"))
            .filter_map(|n| n.text())
            .collect();
        for want in [
            format!("≤ {}", format_length_m(locked.min, 3)),
            format!("≥ {}", format_length_m(locked.max, 3)),
        ] {
            assert!(
                texts.iter().any(|t| t.trim() == want),
                "{want} in {texts:?}"
            );
        }
    }

    fn decode(s: &str) -> Vec<u8> {
        const A: &[u8; 64] = b"ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
        let mut out = Vec::new();
        for q in s.as_bytes().chunks(4) {
            let pad = q.iter().filter(|&&c| c == b'=').count();
            let n = q.iter().fold(0u32, |a, &c| {
                (a << 6) | A.iter().position(|&x| x == c).unwrap_or(0) as u32
            });
            out.extend_from_slice(&[(n >> 16) as u8, (n >> 8) as u8, n as u8][..3 - pad]);
        }
        out
    }
}
