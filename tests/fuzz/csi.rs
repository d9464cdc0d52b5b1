//! Issue 40: the six real Wi-Fi CSI files of tests/data/csi (Intel 5300, PicoScenes, Nexmon
//! pcap, FeitCSI VHT80 and HE160, ESP32 CSV), edited byte-wise — flips, length and count fields
//! set to extremes (0, 1, all ones, the sign bit), truncation, a splice of the file into
//! itself — and read through `csi::read_capture` (the file's own format, and auto) and
//! `csi::to_recording` in process. Invariant: `Ok` with a capture that passes `validate` and a
//! valid recording of finite samples, or a named error (one line, at most 1000 bytes), without
//! reserving what the file only declares (the peak address space grows by at most
//! [`CSI_RESERVE_LIMIT`]), within the in-process time budget.
//!
//! `csi_streams`: the same edited files pushed through `csi::CsiStream` (the reader of `cir
//! track --follow`) in chunks of a random size, then its end. Invariant: every frame out has
//! finite samples, `links × bins` of them as the stream's header says, at increasing times, or
//! a named error — never a panic — and the bytes held between pushes stay within one record.

use proptest::prelude::*;

use super::check::{self, core_err, fail, guarded, Class, Pass, Verdict};
use super::runner::fuzz;
use super::{Case, KNOWN};
use scatterloc::csi::{
    read_capture, to_recording, ConvertOptions, CsiFormat, CsiFrame, CsiStream,
    MAX_CSI_RECORD_BYTES,
};

/// Growth of the peak address space one case may cause (the largest base file is 421 KB and
/// reads into ~2 MB).
const CSI_RESERVE_LIMIT: u64 = 256 << 20;

const FILES: [(&str, CsiFormat); 6] = [
    ("intel/example.dat", CsiFormat::Intel5300),
    ("pico/picoscenes_iwl5300_example.csi", CsiFormat::PicoScenes),
    ("nexmon/example_4366c0.pcap", CsiFormat::Nexmon),
    ("feitcsi/VHT80_5500.csi", CsiFormat::FeitCsi),
    ("feitcsi/HESU160_5500.csi", CsiFormat::FeitCsi),
    ("esp32/example_data.csv", CsiFormat::Esp32),
];

/// One edit; positions are fractions of the first 4 KiB (`head`: where the headers and the
/// first frames are) or of the whole file.
#[derive(Clone, Debug)]
enum Edit {
    Flip {
        at: f64,
        head: bool,
        bit: u8,
    },
    Word {
        at: f64,
        head: bool,
        width: u8,
        value: u32,
    },
    Truncate {
        at: f64,
    },
    Splice {
        from: f64,
        to: f64,
        len: u16,
    },
}

fn edit() -> impl Strategy<Value = Edit> {
    let value = prop_oneof![
        Just(0u32),
        Just(1),
        Just(u32::MAX),
        Just(0x8000_0000),
        Just(0x7fff),
        Just(0xffff),
        any::<u32>()
    ];
    prop_oneof![
        (0.0..1.0f64, any::<bool>(), 0u8..8).prop_map(|(at, head, bit)| Edit::Flip {
            at,
            head,
            bit
        }),
        (
            0.0..1.0f64,
            any::<bool>(),
            prop_oneof![Just(1u8), Just(2), Just(4)],
            value
        )
            .prop_map(|(at, head, width, value)| Edit::Word {
                at,
                head,
                width,
                value
            }),
        (0.0..1.0f64).prop_map(|at| Edit::Truncate { at }),
        (0.0..1.0f64, 0.0..1.0f64, 1u16..2048).prop_map(|(from, to, len)| Edit::Splice {
            from,
            to,
            len
        }),
    ]
}

fn apply(base: &[u8], edits: &[Edit]) -> Vec<u8> {
    let mut z = base.to_vec();
    let pos = |z: &Vec<u8>, at: f64, head: bool| -> usize {
        let n = if head { z.len().min(4096) } else { z.len() };
        ((at * n as f64) as usize).min(n.saturating_sub(1))
    };
    for e in edits {
        if z.is_empty() {
            break;
        }
        match *e {
            Edit::Flip { at, head, bit } => {
                let i = pos(&z, at, head);
                z[i] ^= 1 << bit;
            }
            Edit::Word {
                at,
                head,
                width,
                value,
            } => {
                let i = pos(&z, at, head);
                for k in 0..width as usize {
                    if let Some(b) = z.get_mut(i + k) {
                        *b = (value >> (8 * k)) as u8;
                    }
                }
            }
            Edit::Truncate { at } => {
                let n = (at * z.len() as f64) as usize;
                z.truncate(n);
            }
            Edit::Splice { from, to, len } => {
                let a = pos(&z, from, false);
                let b = pos(&z, to, false);
                let end = (a + len as usize).min(z.len());
                let chunk = z[a..end].to_vec();
                z.splice(b..b, chunk);
            }
        }
    }
    z
}

fn run(z: &[u8], format: Option<CsiFormat>) -> Verdict {
    let before = check::vm_peak_bytes();
    let got = read_capture(z, format);
    if let (Some(a), Some(b)) = (before, check::vm_peak_bytes()) {
        if b > a + CSI_RESERVE_LIMIT {
            return Err(fail(
                Class::OverMemory,
                format!(
                    "the peak address space grew by {} MiB reading a {}-byte file",
                    (b - a) >> 20,
                    z.len()
                ),
            ));
        }
    }
    let cap = match got {
        Ok(c) => c,
        Err(e) => return core_err(&e),
    };
    if let Err(e) = cap.validate() {
        return Err(fail(
            Class::BadOutput,
            format!("read an invalid capture: {e}"),
        ));
    }
    let conv = match to_recording(&cap, &ConvertOptions::default()) {
        Ok(c) => c,
        Err(e) => return core_err(&e),
    };
    if let Err(e) = conv.recording.validate() {
        return Err(fail(Class::BadOutput, format!("an invalid recording: {e}")));
    }
    Ok(Pass::Ok)
}

/// The bytes of [`FILES`], in order.
fn base_files() -> Vec<Vec<u8>> {
    FILES
        .iter()
        .map(|(name, _)| {
            std::fs::read(format!(
                "{}/tests/data/csi/{name}",
                env!("CARGO_MANIFEST_DIR")
            ))
            .expect("a CSI test file")
        })
        .collect()
}

#[test]
fn fuzz_csi_files() {
    let bases = base_files();
    let strategy = (
        0..FILES.len(),
        any::<bool>(),
        prop::collection::vec(edit(), 1..=4),
    );
    fuzz(
        file!(),
        "csi_files",
        600,
        KNOWN,
        strategy,
        |(base, auto, edits)| {
            let (name, format) = FILES[*base];
            let desc = format!("{name} (auto {auto}), edits {edits:?}");
            let z = apply(&bases[*base], edits);
            let f = if *auto { None } else { Some(format) };
            Case {
                verdict: guarded(&desc, || run(&z, f)),
                what: desc,
            }
        },
    );
}

/// `z` through a [`CsiStream`] of `format` in `chunk`-byte pushes (module doc's invariant).
fn run_stream(z: &[u8], format: CsiFormat, chunk: usize) -> Verdict {
    let mut s = match CsiStream::new(format, ConvertOptions::default()) {
        Ok(s) => s,
        Err(e) => return core_err(&e),
    };
    let mut out: Vec<CsiFrame> = Vec::new();
    let mut frames = 0usize;
    let mut last_t = f64::NEG_INFINITY;
    let mut check = |s: &CsiStream, out: &mut Vec<CsiFrame>| -> Result<(), String> {
        if s.pending_bytes() > MAX_CSI_RECORD_BYTES + chunk {
            return Err(format!("{} bytes held between pushes", s.pending_bytes()));
        }
        for f in out.drain(..) {
            let h = s.header().ok_or("a frame before the stream's header")?;
            let want = h.links.len() * h.freq_hz.len();
            if f.samples.len() != want {
                return Err(format!(
                    "frame {frames}: {} samples, the header says {want}",
                    f.samples.len()
                ));
            }
            if !f.t_s.is_finite()
                || f.samples
                    .iter()
                    .any(|c| !(c.re.is_finite() && c.im.is_finite()))
            {
                return Err(format!(
                    "frame {frames}: a sample or its time is not finite"
                ));
            }
            if f.t_s < last_t {
                return Err(format!("frame {frames}: time {} after {last_t}", f.t_s));
            }
            last_t = f.t_s;
            frames += 1;
        }
        Ok(())
    };
    for piece in z.chunks(chunk.max(1)) {
        if let Err(e) = s.push(piece, &mut out) {
            return core_err(&e);
        }
        if let Err(m) = check(&s, &mut out) {
            return Err(fail(Class::BadOutput, m));
        }
    }
    if let Err(e) = s.end(&mut out) {
        return core_err(&e);
    }
    check(&s, &mut out).map_err(|m| fail(Class::BadOutput, m))?;
    Ok(Pass::Ok)
}

#[test]
fn fuzz_csi_streams() {
    let bases = base_files();
    // Chunks from 64 bytes (a pipe's small reads) to 64 KiB (the CLI's read size).
    let strategy = (
        0..FILES.len(),
        prop_oneof![64usize..512, 512usize..65_536],
        prop::collection::vec(edit(), 0..=4),
    );
    fuzz(
        file!(),
        "csi_streams",
        200,
        KNOWN,
        strategy,
        |(base, chunk, edits)| {
            let (name, format) = FILES[*base];
            let desc = format!("{name} in {chunk}-byte pushes, edits {edits:?}");
            let z = apply(&bases[*base], edits);
            Case {
                verdict: guarded(&desc, || run_stream(&z, format, *chunk)),
                what: desc,
            }
        },
    );
}
