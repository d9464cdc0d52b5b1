//! Mutation of a valid JSON document: a case is a base document plus a short list of
//! [`Mutation`]s, each aimed at one node of the document (picked by an index into the list of
//! its nodes at the time it is applied) and doing one thing to it: delete or rename a key, add a
//! key, replace a value by another type or by an extreme number, scale a number, empty, grow or
//! duplicate an array, wrap a value in deep nesting. Values that JSON (or `serde_json::Value`)
//! cannot hold — `-0` as an integer, `1e400`, 10⁵-digit integers, `NaN`, lone surrogates, very
//! deep nesting — are spliced into the serialised text as raw tokens.
//!
//! Every size is bounded (arrays to [`MAX_GROW`] elements, the whole document to
//! [`MAX_DOC_NODES`] nodes, strings to [`LONG_STRING`] bytes, nesting to 300 levels) so one case
//! stays cheap.

use proptest::prelude::*;
use proptest::sample::Index;
use serde_json::{Map, Value};

/// Longest generated string (a key, a value, a name): 1 MB, echoed in full by an error message
/// that does not truncate.
pub const LONG_STRING: usize = 1 << 20;
/// Most elements an array may grow to (a few hundred for most, one long case per list).
pub const MAX_GROW: usize = 20_000;
/// Most nodes a mutated document may have (about 5 MB of JSON): a mutation that would take it
/// past this is skipped. Growth compounds (a list of lists grown, then every inner list grown),
/// and an unbounded case once asked for 4.3 GB in the test process itself.
pub const MAX_DOC_NODES: usize = 200_000;

/// Numbers at and beyond the edges: zeros, subnormals, the largest finite values, huge
/// integers, negative counts, and a few plain ones so that a "small" change also occurs.
pub const EXTREMES: &[f64] = &[
    0.0,
    -0.0,
    1e-320,
    -1e-320,
    5e-324,
    -5e-324,
    1e-300,
    1e308,
    -1e308,
    f64::MAX,
    f64::MIN,
    1e300,
    1e15,
    -1e15,
    1e9,
    1e7,
    1.0000001e7,
    -1.0000001e7,
    1e-15,
    1e-9,
    -1e-9,
    1e-3,
    1e3,
    -1.0,
    0.5,
    1.0,
    2.0,
    3.0,
    360.0,
    361.0,
    -180.0,
    4294967296.0,
    9007199254740993.0,
];

/// Raw JSON tokens spliced into the text (some are not valid JSON on purpose).
pub fn raw_tokens() -> &'static [String] {
    static TOKENS: std::sync::OnceLock<Vec<String>> = std::sync::OnceLock::new();
    TOKENS.get_or_init(|| {
        vec![
            "-0".into(),
            "1e400".into(),
            "-1e400".into(),
            "1e-400".into(),
            "123456789012345678901234567890".into(),
            "-9223372036854775809".into(),
            "18446744073709551616".into(),
            "2.4703282292062328e-324".into(),
            "1.7976931348623159e308".into(),
            format!("1{}", "0".repeat(100_000)),
            format!("0.{}1", "0".repeat(100_000)),
            "NaN".into(),
            "Infinity".into(),
            "-Infinity".into(),
            "\"\\ud800\"".into(),
            "\"\\u0000\"".into(),
            format!("{}1{}", "[".repeat(300), "]".repeat(300)),
            format!(
                "{}{}",
                "{\"a\":".repeat(200),
                format!("1{}", "}".repeat(200))
            ),
            "01".into(),
            "1.".into(),
            "+1".into(),
            "truefalse".into(),
        ]
    })
}

/// A generated value.
#[derive(Clone, Debug)]
pub enum Gen {
    Null,
    Bool(bool),
    Num(f64),
    U64(u64),
    I64(i64),
    /// A string of `len` copies of `ch`.
    Str(usize, char),
    /// A number as a string (`"3.5"`).
    NumStr(f64),
    EmptyArr,
    EmptyObj,
    /// An array holding `n` copies of a small number.
    Arr(usize),
    /// `depth` nested arrays around a number.
    Nested(usize),
    /// Raw token `raw_tokens()[i]`.
    Raw(usize),
}

fn gen() -> impl Strategy<Value = Gen> {
    prop_oneof![
        1 => Just(Gen::Null),
        1 => any::<bool>().prop_map(Gen::Bool),
        3 => prop::sample::select(EXTREMES).prop_map(Gen::Num),
        1 => prop::sample::select(&[0, 1, u64::MAX, 1 << 53, (1 << 53) + 1, u32::MAX as u64 + 1][..])
            .prop_map(Gen::U64),
        1 => prop::sample::select(&[-1, i64::MIN, -(1 << 40)][..]).prop_map(Gen::I64),
        1 => (
            prop::sample::select(&[0, 1, 12, 300, 5000, LONG_STRING][..]),
            prop::sample::select(&['a', 'é', '"', '\\', '\n', '\u{7f}', '💥', ' '][..])
        )
            .prop_map(|(n, c)| Gen::Str(n, c)),
        1 => prop::sample::select(EXTREMES).prop_map(Gen::NumStr),
        1 => Just(Gen::EmptyArr),
        1 => Just(Gen::EmptyObj),
        1 => prop::sample::select(&[1, 2, 3, 4, 7, 64][..]).prop_map(Gen::Arr),
        1 => prop::sample::select(&[2, 20, 127, 129, 300][..]).prop_map(Gen::Nested),
        2 => (0..raw_tokens().len()).prop_map(Gen::Raw),
    ]
}

/// How a key is renamed.
#[derive(Clone, Debug)]
pub enum KeyMut {
    /// Drop the last character (a typo).
    Truncate,
    /// Append a suffix.
    Suffix(&'static str),
    Upper,
    Empty,
    /// A long key of `n` bytes.
    Long(usize),
    /// The name of a sibling key (a duplicate once serialised is impossible in a map, so this
    /// overwrites the sibling).
    Sibling(Index),
}

fn key_mut() -> impl Strategy<Value = KeyMut> {
    prop_oneof![
        Just(KeyMut::Truncate),
        prop::sample::select(&["_", "s", "_m", " ", "\u{0}", "é"][..]).prop_map(KeyMut::Suffix),
        Just(KeyMut::Upper),
        Just(KeyMut::Empty),
        prop::sample::select(&[300, LONG_STRING][..]).prop_map(KeyMut::Long),
        any::<Index>().prop_map(KeyMut::Sibling),
    ]
}

/// One mutation.
#[derive(Clone, Debug)]
pub enum Op {
    /// Remove the node from its parent (object member or array element).
    Delete,
    /// Rename the node's key (object members only; otherwise nothing).
    Rename(KeyMut),
    /// Add a key to the node if it is an object (else to its parent object).
    AddKey(KeyMut, Gen),
    /// Replace the node by a generated value.
    Replace(Gen),
    /// Multiply a number by a factor (other nodes: replaced by the factor).
    Scale(f64),
    /// Add a small offset to a number (near-valid changes).
    Nudge(f64),
    /// Empty an array or object.
    Empty,
    /// Append copies (numbers perturbed) of an array's elements up to `n` elements.
    Grow(usize),
    /// `Grow(n)` applied to the node and every array sibling in the same parent array.
    GrowSiblings(usize),
    /// Duplicate the node in its parent array.
    Duplicate,
    /// Wrap the node in `n` arrays.
    Wrap(usize),
    /// A number becomes its string, a string its length, a bool a number, an array its first
    /// element, an object its first value.
    SwapType,
}

fn op(grow_cap: usize) -> impl Strategy<Value = Op> {
    let grow = prop_oneof![
        4 => prop::sample::select(&[2usize, 3, 5, 9, 17, 50, 65, 257][..]),
        1 => prop::sample::select(&[1000usize, MAX_GROW][..]),
    ]
    .prop_map(move |n| n.min(grow_cap));
    prop_oneof![
        3 => Just(Op::Delete),
        2 => key_mut().prop_map(Op::Rename),
        1 => (key_mut(), gen()).prop_map(|(k, g)| Op::AddKey(k, g)),
        4 => gen().prop_map(Op::Replace),
        2 => prop::sample::select(&[0.0, -1.0, 1e-300, 1e300, 1e6, 1e-6, 1.0 + 1e-15, 1e12][..])
            .prop_map(Op::Scale),
        1 => prop::sample::select(&[1e-12, -1e-12, 0.5, -0.5, 10.0, -100.0][..]).prop_map(Op::Nudge),
        1 => Just(Op::Empty),
        2 => grow.clone().prop_map(Op::Grow),
        1 => grow.prop_map(Op::GrowSiblings),
        1 => Just(Op::Duplicate),
        1 => prop::sample::select(&[1usize, 3, 200][..]).prop_map(Op::Wrap),
        1 => Just(Op::SwapType),
    ]
}

/// A mutation aimed at node `target` (index into the document's nodes in pre-order).
#[derive(Clone, Debug)]
pub struct Mutation {
    pub target: Index,
    pub op: Op,
}

/// Up to `max` mutations (0 = the valid document itself, kept as a baseline case); arrays grow
/// to at most `grow_cap` elements.
pub fn mutations(max: usize, grow_cap: usize) -> impl Strategy<Value = Vec<Mutation>> {
    prop::collection::vec(
        (any::<Index>(), op(grow_cap)).prop_map(|(target, op)| Mutation { target, op }),
        0..=max,
    )
}

/// A step of a path into a document.
#[derive(Clone, Debug, PartialEq)]
enum Seg {
    Key(String),
    At(usize),
}

fn paths(v: &Value, here: &mut Vec<Seg>, out: &mut Vec<Vec<Seg>>) {
    out.push(here.clone());
    match v {
        Value::Array(a) => {
            // Long arrays: visit the first few and the last elements only (keeps the node list
            // and therefore the chance of hitting the document's other fields reasonable).
            let n = a.len();
            for i in (0..n).filter(|&i| i < 8 || i + 2 >= n) {
                here.push(Seg::At(i));
                paths(&a[i], here, out);
                here.pop();
            }
        }
        Value::Object(m) => {
            for (k, x) in m {
                here.push(Seg::Key(k.clone()));
                paths(x, here, out);
                here.pop();
            }
        }
        _ => {}
    }
}

fn get_mut<'a>(v: &'a mut Value, path: &[Seg]) -> Option<&'a mut Value> {
    let mut cur = v;
    for s in path {
        cur = match (s, cur) {
            (Seg::Key(k), Value::Object(m)) => m.get_mut(k)?,
            (Seg::At(i), Value::Array(a)) => a.get_mut(*i)?,
            _ => return None,
        };
    }
    Some(cur)
}

/// The mutated document as text, and a short description of what was done (for reports).
pub struct Mutated {
    pub text: String,
    pub what: Vec<String>,
}

struct Ctx {
    raws: Vec<usize>,
}

impl Ctx {
    fn value(&mut self, g: &Gen) -> Value {
        match *g {
            Gen::Null => Value::Null,
            Gen::Bool(b) => Value::Bool(b),
            Gen::Num(x) => num(x),
            Gen::U64(x) => Value::from(x),
            Gen::I64(x) => Value::from(x),
            Gen::Str(n, c) => Value::String(long(n, c)),
            Gen::NumStr(x) => Value::String(format!("{x}")),
            Gen::EmptyArr => Value::Array(vec![]),
            Gen::EmptyObj => Value::Object(Map::new()),
            Gen::Arr(n) => Value::Array(vec![num(1.5); n]),
            Gen::Nested(d) => (0..d).fold(num(1.0), |v, _| Value::Array(vec![v])),
            Gen::Raw(i) => {
                self.raws.push(i);
                Value::String(marker(self.raws.len() - 1))
            }
        }
    }

    fn key(&mut self, k: &KeyMut, old: &str, siblings: &[String]) -> String {
        match k {
            KeyMut::Truncate => {
                let mut s = old.to_string();
                s.pop();
                s
            }
            KeyMut::Suffix(x) => format!("{old}{x}"),
            KeyMut::Upper => old.to_uppercase(),
            KeyMut::Empty => String::new(),
            KeyMut::Long(n) => long(*n, 'k'),
            KeyMut::Sibling(i) if !siblings.is_empty() => siblings[i.index(siblings.len())].clone(),
            KeyMut::Sibling(_) => format!("{old}2"),
        }
    }
}

fn long(n: usize, c: char) -> String {
    let mut s = String::new();
    while s.len() < n {
        s.push(c);
    }
    s
}

fn marker(i: usize) -> String {
    format!("@@RAW{i}@@")
}

fn num(x: f64) -> Value {
    // Integral values that fit stay integers (as a user would write them); the rest are floats.
    if x == x.trunc() && x.abs() < 9.0e15 && !(x == 0.0 && x.is_sign_negative()) {
        Value::from(x as i64)
    } else {
        serde_json::Number::from_f64(x).map_or(Value::Null, Value::Number)
    }
}

fn perturb(v: &Value, k: usize) -> Value {
    match v {
        Value::Number(n) => {
            let x = n.as_f64().unwrap_or(0.0);
            let f = 1.0 + 0.013 * ((k * 7919) % 97) as f64 / 97.0;
            num(if n.is_f64() || x.fract() != 0.0 {
                x * f
            } else {
                x
            })
        }
        Value::Array(a) => Value::Array(a.iter().map(|x| perturb(x, k)).collect()),
        other => other.clone(),
    }
}

fn grow(v: &mut Value, n: usize) {
    if let Value::Array(a) = v {
        if a.is_empty() {
            a.push(num(1.0));
        }
        let m = a.len();
        let mut k = 0;
        while a.len() < n {
            let x = perturb(&a[k % m], k + 1);
            a.push(x);
            k += 1;
        }
    }
}

/// Applies `muts` to `base`.
pub fn apply(base: &Value, muts: &[Mutation]) -> Mutated {
    let mut doc = base.clone();
    let mut ctx = Ctx { raws: vec![] };
    let mut what = vec![];
    for m in muts {
        let mut all = vec![];
        paths(&doc, &mut vec![], &mut all);
        let path = all[m.target.index(all.len())].clone();
        let before = doc.clone();
        let raws = ctx.raws.len();
        apply_one(&mut doc, &path, &m.op, &mut ctx);
        if nodes(&doc) > MAX_DOC_NODES {
            doc = before;
            ctx.raws.truncate(raws);
            what.push(format!(
                "{}: {} (skipped: too large)",
                show(&path),
                op_name(&m.op)
            ));
        } else {
            what.push(format!("{}: {}", show(&path), op_name(&m.op)));
        }
    }
    let mut text = serde_json::to_string(&doc).expect("serialise");
    for (i, &r) in ctx.raws.iter().enumerate() {
        text = text.replacen(&format!("\"{}\"", marker(i)), &raw_tokens()[r], 1);
    }
    Mutated { text, what }
}

/// The number of nodes of `v` (itself, and every element and value below it).
fn nodes(v: &Value) -> usize {
    1 + match v {
        Value::Array(a) => a.iter().map(nodes).sum(),
        Value::Object(m) => m.values().map(nodes).sum(),
        _ => 0,
    }
}

fn show(path: &[Seg]) -> String {
    let mut s = String::from("$");
    for p in path {
        match p {
            Seg::Key(k) if k.len() > 40 => s.push_str(&format!(".<key of {} bytes>", k.len())),
            Seg::Key(k) => s.push_str(&format!(".{k}")),
            Seg::At(i) => s.push_str(&format!("[{i}]")),
        }
    }
    s
}

fn op_name(op: &Op) -> String {
    let g = |g: &Gen| match g {
        Gen::Str(n, c) => format!("Str({n} × {c:?})"),
        Gen::Raw(i) => {
            let t = &raw_tokens()[*i];
            if t.len() > 40 {
                format!("Raw({}… of {} bytes)", &t[..12], t.len())
            } else {
                format!("Raw({t})")
            }
        }
        other => format!("{other:?}"),
    };
    match op {
        Op::Replace(x) => format!("Replace({})", g(x)),
        Op::AddKey(k, x) => format!("AddKey({k:?}, {})", g(x)),
        other => format!("{other:?}"),
    }
}

fn apply_one(doc: &mut Value, path: &[Seg], op: &Op, ctx: &mut Ctx) {
    let (parent_path, last) = match path.split_last() {
        Some((l, p)) => (p, Some(l)),
        None => (path, None),
    };
    match op {
        Op::Delete | Op::Duplicate | Op::Rename(_) => {
            let Some(last) = last else { return };
            let Some(parent) = get_mut(doc, parent_path) else {
                return;
            };
            match (parent, last, op) {
                (Value::Object(m), Seg::Key(k), Op::Delete) => {
                    m.remove(k);
                }
                (Value::Array(a), Seg::At(i), Op::Delete) => {
                    a.remove(*i);
                }
                (Value::Array(a), Seg::At(i), Op::Duplicate) => {
                    let x = a[*i].clone();
                    a.insert(*i, x);
                }
                (Value::Object(m), Seg::Key(k), Op::Rename(km)) => {
                    let siblings: Vec<String> = m.keys().filter(|s| *s != k).cloned().collect();
                    let new = ctx.key(km, k, &siblings);
                    if let Some(x) = m.remove(k) {
                        m.insert(new, x);
                    }
                }
                _ => {}
            }
        }
        Op::AddKey(km, g) => {
            let v = ctx.value(g);
            let target = match get_mut(doc, path) {
                Some(Value::Object(_)) => path,
                _ => parent_path,
            };
            if let Some(Value::Object(m)) = get_mut(doc, target) {
                let siblings: Vec<String> = m.keys().cloned().collect();
                let k = ctx.key(km, "extra", &siblings);
                m.insert(k, v);
            }
        }
        Op::Replace(g) => {
            let v = ctx.value(g);
            if let Some(x) = get_mut(doc, path) {
                *x = v;
            }
        }
        Op::Scale(f) | Op::Nudge(f) => {
            if let Some(x) = get_mut(doc, path) {
                *x = match (&*x, op) {
                    (Value::Number(n), Op::Scale(_)) => num(n.as_f64().unwrap_or(0.0) * f),
                    (Value::Number(n), _) => num(n.as_f64().unwrap_or(0.0) + f),
                    _ => num(*f),
                };
            }
        }
        Op::Empty => match get_mut(doc, path) {
            Some(Value::Array(a)) => a.clear(),
            Some(Value::Object(m)) => m.clear(),
            Some(x) => *x = Value::Array(vec![]),
            None => {}
        },
        Op::Grow(n) => {
            if let Some(x) = get_mut(doc, path) {
                grow(x, *n);
            }
        }
        Op::GrowSiblings(n) => {
            let is_elem = matches!(last, Some(Seg::At(_)));
            match get_mut(doc, parent_path) {
                Some(Value::Array(a)) if is_elem => a.iter_mut().for_each(|x| grow(x, *n)),
                _ => {
                    if let Some(x) = get_mut(doc, path) {
                        grow(x, *n);
                    }
                }
            }
        }
        Op::Wrap(n) => {
            if let Some(x) = get_mut(doc, path) {
                for _ in 0..*n {
                    *x = Value::Array(vec![x.take()]);
                }
            }
        }
        Op::SwapType => {
            if let Some(x) = get_mut(doc, path) {
                *x = match x.take() {
                    Value::Number(n) => Value::String(n.to_string()),
                    Value::String(s) => Value::from(s.len()),
                    Value::Bool(b) => Value::from(u8::from(b)),
                    Value::Null => Value::from(0),
                    Value::Array(mut a) if !a.is_empty() => a.swap_remove(0),
                    Value::Array(_) => Value::Null,
                    Value::Object(m) => m.into_iter().next().map_or(Value::Null, |(_, v)| v),
                };
            }
        }
    }
}
