//! The digest of a part's sums (issue 24): one pass over their JSON text that allocates nothing
//! for the values, hashing them as a canonical token stream (structure, strings, numbers by
//! type and bits; not the layout or the key order) and refusing arrays longer than the study
//! implies before anything is allocated for them.

use alloc::format;
use alloc::string::{String, ToString};
use alloc::vec::Vec;

use serde::de::{DeserializeSeed, MapAccess, SeqAccess, Visitor};
use serde::Serialize;
use sha2::{Digest, Sha256};

use super::message::at_path;

/// The `digest` of a part file with sums `sums`: `sha256:` and the hex SHA-256 of their JSON
/// as a canonical token stream (structure, strings, numbers by type and bits; not the layout
/// or the key order, so a reformatted part keeps its digest). Errors are serde_json's (sums
/// that do not serialize).
pub fn sums_digest<S: Serialize + ?Sized>(sums: &S) -> core::result::Result<String, String> {
    let text = serde_json::to_string(sums).map_err(|e| format!("encoding the sums: {e}"))?;
    walk("sums", &text, usize::MAX).map(|d| hex(&d))
}

/// Walks the JSON text `raw` once without allocating for its values: checks that no array
/// (nested at any depth) has more than `max` entries, and returns the SHA-256 of its values
/// as a canonical token stream (the value's structure, strings, numbers by type and bits;
/// an object's entries in any order — whitespace, layout and key order do not count; an
/// object of more than `max` keys is refused too). The error
/// names the path under `what` (`sums[0].squared_error: more than 11 entries …`).
pub(super) fn walk(what: &str, raw: &str, max: usize) -> core::result::Result<[u8; 32], String> {
    struct Shape<'h> {
        max: usize,
        h: &'h mut Sha256,
    }
    impl<'de> DeserializeSeed<'de> for Shape<'_> {
        type Value = ();
        fn deserialize<D: serde::Deserializer<'de>>(
            self,
            d: D,
        ) -> core::result::Result<(), D::Error> {
            d.deserialize_any(self)
        }
    }
    impl<'de> Visitor<'de> for Shape<'_> {
        type Value = ();
        fn expecting(&self, f: &mut core::fmt::Formatter) -> core::fmt::Result {
            f.write_str("any JSON value")
        }
        fn visit_bool<E>(self, v: bool) -> core::result::Result<(), E> {
            self.h.update([b'b', v as u8]);
            Ok(())
        }
        fn visit_i64<E>(self, v: i64) -> core::result::Result<(), E> {
            self.h.update([b'i']);
            self.h.update(v.to_le_bytes());
            Ok(())
        }
        fn visit_u64<E>(self, v: u64) -> core::result::Result<(), E> {
            self.h.update([b'u']);
            self.h.update(v.to_le_bytes());
            Ok(())
        }
        fn visit_f64<E>(self, v: f64) -> core::result::Result<(), E> {
            self.h.update([b'f']);
            self.h.update(v.to_bits().to_le_bytes());
            Ok(())
        }
        fn visit_str<E>(self, v: &str) -> core::result::Result<(), E> {
            self.h.update([b's']);
            self.h.update((v.len() as u64).to_le_bytes());
            self.h.update(v.as_bytes());
            Ok(())
        }
        fn visit_unit<E>(self) -> core::result::Result<(), E> {
            self.h.update([b'n']);
            Ok(())
        }
        fn visit_seq<A: SeqAccess<'de>>(self, mut seq: A) -> core::result::Result<(), A::Error> {
            let Shape { max, h } = self;
            h.update([b'[']);
            let mut n = 0usize;
            while seq.next_element_seed(Shape { max, h: &mut *h })?.is_some() {
                n += 1;
                if n > max {
                    return Err(serde::de::Error::custom(format!(
                        "more than {max} entries (the most the study's configuration implies)"
                    )));
                }
            }
            h.update([b']']);
            Ok(())
        }
        fn visit_map<A: MapAccess<'de>>(self, mut map: A) -> core::result::Result<(), A::Error> {
            // Each entry hashed on its own, the entries' hashes sorted: key order does not
            // count (a tool that sorts keys keeps the digest).
            let Shape { max, h } = self;
            let mut entries: Vec<[u8; 32]> = Vec::new();
            loop {
                let mut e = Sha256::new();
                if map.next_key_seed(Shape { max, h: &mut e })?.is_none() {
                    break;
                }
                map.next_value_seed(Shape { max, h: &mut e })?;
                entries.push(e.finalize().into());
                if entries.len() > max {
                    return Err(serde::de::Error::custom(format!(
                        "more than {max} keys (the most the study's configuration implies)"
                    )));
                }
            }
            entries.sort_unstable();
            h.update([b'{']);
            for e in &entries {
                h.update(e);
            }
            h.update([b'}']);
            Ok(())
        }
    }
    let mut h = Sha256::new();
    let mut de = serde_json::Deserializer::from_str(raw);
    let mut track = serde_path_to_error::Track::new();
    Shape { max, h: &mut h }
        .deserialize(serde_path_to_error::Deserializer::new(&mut de, &mut track))
        .map_err(|e| at_path(what, &track.path().to_string(), e))?;
    Ok(h.finalize().into())
}

/// `sha256:` and 64 hex digits.
pub(super) fn hex(d: &[u8; 32]) -> String {
    let mut s = String::from("sha256:");
    for b in d {
        s.push_str(&format!("{b:02x}"));
    }
    s
}
