//! One `.npy` array: parsing its header and reading its elements, and writing one.

use alloc::format;
use alloc::string::{String, ToString};
use alloc::vec::Vec;

use crate::error::{Error, Result};
use crate::math::{Complex, Real};

pub(super) fn invalid(field: &str, reason: String) -> Error {
    Error::InvalidFile {
        field: field.into(),
        reason,
    }
}

const MAGIC: &[u8] = b"\x93NUMPY";

/// An element type: kind `f` (float), `i` (signed integer) or `c` (complex), its size in bytes
/// and byte order.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(super) struct Dtype {
    pub kind: u8,
    pub size: usize,
    pub big_endian: bool,
}

impl Dtype {
    /// numpy's name of the type, e.g. `complex128`.
    pub fn name(&self) -> String {
        match self.kind {
            b'f' => format!("float{}", self.size * 8),
            b'i' => format!("int{}", self.size * 8),
            b'c' => format!("complex{}", self.size * 8),
            b'u' => format!("uint{}", self.size * 8),
            b'b' => "bool".into(),
            k => format!("'{}{}'", k as char, self.size),
        }
    }
}

/// A parsed `.npy` member: its type, shape and the raw little/big-endian element bytes.
pub(super) struct Npy {
    pub name: String,
    pub dtype: Dtype,
    pub shape: Vec<usize>,
    pub data: Vec<u8>,
}

fn parse_descr(name: &str, d: &str) -> Result<Dtype> {
    let b = d.as_bytes();
    let bad = || invalid(name, format!("unsupported dtype descr '{d}'"));
    if b.len() < 3 {
        return Err(bad());
    }
    let big_endian = match b[0] {
        b'<' | b'|' | b'=' => false,
        b'>' => true,
        _ => return Err(bad()),
    };
    // Bytes, not `&d[2..]`: a multi-byte second character must be an error, not a panic.
    let size: usize = core::str::from_utf8(&b[2..])
        .ok()
        .and_then(|t| t.parse().ok())
        .ok_or_else(bad)?;
    Ok(Dtype {
        kind: b[1],
        size,
        big_endian,
    })
}

/// Parses the header dict `{'descr': '<c16', 'fortran_order': False, 'shape': (3, 4), }`.
fn parse_header(name: &str, h: &str) -> Result<(Dtype, bool, Vec<usize>)> {
    let bad = |what: &str| invalid(name, format!("not a .npy array: bad header ({what})"));
    let h = h.trim();
    let inner = h
        .strip_prefix('{')
        .and_then(|r| r.strip_suffix('}'))
        .ok_or_else(|| bad("not a dict"))?;
    let (mut descr, mut fortran, mut shape) = (None, None, None);
    let mut rest = inner.trim_start();
    while !rest.is_empty() {
        let q = rest.chars().next().unwrap_or(' ');
        if q != '\'' && q != '"' {
            return Err(bad("key"));
        }
        let end = rest[1..].find(q).ok_or_else(|| bad("key"))? + 1;
        let key = &rest[1..end];
        rest = rest[end + 1..].trim_start();
        rest = rest
            .strip_prefix(':')
            .ok_or_else(|| bad("':'"))?
            .trim_start();
        match key {
            "descr" => {
                let q = rest.chars().next().unwrap_or(' ');
                if q != '\'' && q != '"' {
                    return Err(invalid(
                        name,
                        "unsupported dtype: a structured array (descr is not a string)".into(),
                    ));
                }
                let end = rest[1..].find(q).ok_or_else(|| bad("descr"))? + 1;
                descr = Some(parse_descr(name, &rest[1..end])?);
                rest = &rest[end + 1..];
            }
            "fortran_order" => {
                if let Some(r) = rest.strip_prefix("True") {
                    fortran = Some(true);
                    rest = r;
                } else if let Some(r) = rest.strip_prefix("False") {
                    fortran = Some(false);
                    rest = r;
                } else {
                    return Err(bad("fortran_order"));
                }
            }
            "shape" => {
                let r = rest.strip_prefix('(').ok_or_else(|| bad("shape"))?;
                let end = r.find(')').ok_or_else(|| bad("shape"))?;
                let mut dims = Vec::new();
                for t in r[..end].split(',') {
                    let t = t.trim();
                    if !t.is_empty() {
                        dims.push(t.parse::<usize>().map_err(|_| bad("shape"))?);
                    }
                }
                shape = Some(dims);
                rest = &r[end + 1..];
            }
            _ => return Err(bad("unknown key")),
        }
        rest = rest.trim_start();
        rest = rest.strip_prefix(',').unwrap_or(rest).trim_start();
    }
    match (descr, fortran, shape) {
        (Some(d), Some(f), Some(s)) => Ok((d, f, s)),
        _ => Err(bad("missing descr, fortran_order or shape")),
    }
}

/// Parses the header of member `name` and returns it with the element bytes, checking that the
/// body holds exactly `product(shape)·size` bytes and that the array is C-ordered.
pub(super) fn parse(name: &str, bytes: Vec<u8>) -> Result<Npy> {
    if bytes.len() < 10 || &bytes[..6] != MAGIC {
        return Err(invalid(
            name,
            "not a .npy array (no \\x93NUMPY magic)".into(),
        ));
    }
    let (len, start): (usize, usize) = match bytes[6] {
        1 => (u16::from_le_bytes([bytes[8], bytes[9]]) as usize, 10),
        2 | 3 if bytes.len() >= 12 => (
            u32::from_le_bytes([bytes[8], bytes[9], bytes[10], bytes[11]]) as usize,
            12,
        ),
        v => return Err(invalid(name, format!("not a .npy array (version {v})"))),
    };
    let end = start
        .checked_add(len)
        .filter(|&e| e <= bytes.len())
        .ok_or_else(|| invalid(name, "not a .npy array (truncated header)".into()))?;
    let header = core::str::from_utf8(&bytes[start..end])
        .map_err(|_| invalid(name, "not a .npy array (header is not text)".into()))?;
    let (dtype, fortran, shape) = parse_header(name, header)?;
    if fortran && shape.len() > 1 {
        return Err(invalid(
            name,
            "fortran_order = True is not supported: write a C-ordered array \
             (numpy.ascontiguousarray)"
                .into(),
        ));
    }
    let count = shape
        .iter()
        .try_fold(1usize, |a, &d| a.checked_mul(d))
        .and_then(|c| c.checked_mul(dtype.size))
        .ok_or_else(|| invalid(name, "shape too large".into()))?;
    let body = bytes.len() - end;
    if body != count {
        return Err(invalid(
            name,
            format!(
                "the data holds {body} bytes, the shape {} of {} needs {count}",
                shape_text(&shape),
                dtype.name()
            ),
        ));
    }
    let mut data = bytes;
    data.drain(..end);
    Ok(Npy {
        name: name.to_string(),
        dtype,
        shape,
        data,
    })
}

/// A shape as numpy prints it: `(3, 4)`, `(5,)`, `()`.
pub(super) fn shape_text(s: &[usize]) -> String {
    match s {
        [] => "()".into(),
        [a] => format!("({a},)"),
        _ => {
            let v: Vec<String> = s.iter().map(|d| d.to_string()).collect();
            format!("({})", v.join(", "))
        }
    }
}

fn chunk<const N: usize>(b: &[u8], big: bool) -> [u8; N] {
    let mut a = [0u8; N];
    a.copy_from_slice(b);
    if big {
        a.reverse();
    }
    a
}

impl Npy {
    fn wrong_dtype(&self, expected: &str) -> Error {
        invalid(
            &self.name,
            format!("wrong dtype {}, expected {expected}", self.dtype.name()),
        )
    }

    /// `Ok` when the shape is `expected`, else an error showing both.
    pub fn expect_shape(&self, expected: &[usize], names: &str) -> Result<()> {
        if self.shape != expected {
            return Err(invalid(
                &self.name,
                format!(
                    "wrong shape {}, expected {names} = {}",
                    shape_text(&self.shape),
                    shape_text(expected)
                ),
            ));
        }
        Ok(())
    }

    /// The elements as float64 (the array must be float64).
    pub fn f64s(&self) -> Result<Vec<Real>> {
        if self.dtype.kind != b'f' || self.dtype.size != 8 {
            return Err(self.wrong_dtype("float64"));
        }
        let big = self.dtype.big_endian;
        Ok(self
            .data
            .chunks_exact(8)
            .map(|c| f64::from_le_bytes(chunk::<8>(c, big)))
            .collect())
    }

    /// The elements as integers (`allowed`: the accepted sizes in bytes, e.g. `[4, 8]`).
    pub fn ints(&self, allowed: &[usize], expected: &str) -> Result<Vec<i64>> {
        if self.dtype.kind != b'i' || !allowed.contains(&self.dtype.size) {
            return Err(self.wrong_dtype(expected));
        }
        let big = self.dtype.big_endian;
        let n = self.dtype.size;
        Ok(self
            .data
            .chunks_exact(n)
            .map(|c| match n {
                2 => i16::from_le_bytes(chunk::<2>(c, big)) as i64,
                4 => i32::from_le_bytes(chunk::<4>(c, big)) as i64,
                _ => i64::from_le_bytes(chunk::<8>(c, big)),
            })
            .collect())
    }

    /// The one element of a bool (`|b1`) or integer array as a flag: 0 is `false`, 1 `true`;
    /// any other value is an error.
    pub fn flag(&self) -> Result<bool> {
        let v = match (self.dtype.kind, self.dtype.size) {
            (b'b', 1) | (b'u', 1) => self.data.first().map(|&b| i64::from(b)),
            (b'i', 1) => self.data.first().map(|&b| i64::from(b as i8)),
            (b'i', _) => self
                .ints(&[2, 4, 8], "bool or int")
                .ok()
                .and_then(|v| v.first().copied()),
            _ => None,
        };
        match v {
            Some(0) => Ok(false),
            Some(1) => Ok(true),
            Some(x) => Err(invalid(
                &self.name,
                format!("{x}: must be 0 (free-running) or 1 (a common clock)"),
            )),
            None => Err(self.wrong_dtype("bool or int")),
        }
    }

    /// Whether the array is complex64 or complex128.
    pub fn is_complex(&self) -> bool {
        self.dtype.kind == b'c' && (self.dtype.size == 8 || self.dtype.size == 16)
    }

    /// The elements as complex (the array must be complex64 or complex128).
    pub fn complexes(&self) -> Result<Vec<Complex>> {
        if !self.is_complex() {
            return Err(self.wrong_dtype("complex64 or complex128"));
        }
        let big = self.dtype.big_endian;
        let half = self.dtype.size / 2;
        Ok(self
            .data
            .chunks_exact(self.dtype.size)
            .map(|c| {
                let (re, im) = c.split_at(half);
                if half == 4 {
                    Complex::new(
                        f32::from_le_bytes(chunk::<4>(re, big)) as Real,
                        f32::from_le_bytes(chunk::<4>(im, big)) as Real,
                    )
                } else {
                    Complex::new(
                        f64::from_le_bytes(chunk::<8>(re, big)),
                        f64::from_le_bytes(chunk::<8>(im, big)),
                    )
                }
            })
            .collect())
    }
}

/// A `.npy` file (version 1.0, little-endian) of `shape` with `descr` and the element bytes.
pub(super) fn write(descr: &str, shape: &[usize], data: &[u8]) -> Vec<u8> {
    let mut h = format!(
        "{{'descr': '{descr}', 'fortran_order': False, 'shape': {}, }}",
        shape_text(shape)
    );
    // magic (6) + version (2) + length (2) + header + '\n', padded to a multiple of 64.
    let total = (10 + h.len() + 1).div_ceil(64) * 64;
    while 10 + h.len() + 1 < total {
        h.push(' ');
    }
    h.push('\n');
    let mut out = Vec::with_capacity(10 + h.len() + data.len());
    out.extend_from_slice(MAGIC);
    out.extend_from_slice(&[1, 0]);
    out.extend_from_slice(&(h.len() as u16).to_le_bytes());
    out.extend_from_slice(h.as_bytes());
    out.extend_from_slice(data);
    out
}
