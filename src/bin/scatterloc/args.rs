//! A small hand-rolled parser: positional words, `--flag VALUE` / `--flag=VALUE` options and
//! value-less `--switch`es, each subcommand declaring which it takes. Errors name the flag.

use std::ffi::OsString;

use crate::CliError;

/// Parsed command line of one subcommand.
#[derive(Debug, Default)]
pub struct Args {
    /// Words that are not options, in order.
    pub positional: Vec<String>,
    /// `(flag, value)` pairs, flag without the leading dashes.
    flags: Vec<(String, String)>,
    /// Switches given (names without dashes).
    switches: Vec<String>,
    /// `--help` or `-h` was given.
    pub help: bool,
}

impl Args {
    /// Parses `argv` (without the program name and subcommand) accepting only `allowed` flags
    /// (names without dashes), each of which takes a value, and the value-less `switches`.
    pub fn parse(
        argv: &[OsString],
        command: &str,
        allowed: &[&str],
        switches: &[&str],
    ) -> Result<Args, CliError> {
        let mut out = Args::default();
        let mut it = argv.iter();
        while let Some(raw) = it.next() {
            let arg = raw.to_str().ok_or_else(|| {
                CliError::usage(format!("{command}: argument is not valid UTF-8"))
            })?;
            if arg == "--help" || arg == "-h" {
                out.help = true;
                continue;
            }
            let Some(body) = arg.strip_prefix("--") else {
                if arg.len() > 1 && arg.starts_with('-') && arg.parse::<f64>().is_err() {
                    return Err(unknown(command, arg));
                }
                out.positional.push(arg.to_string());
                continue;
            };
            let (name, inline) = match body.split_once('=') {
                Some((n, v)) => (n, Some(v.to_string())),
                None => (body, None),
            };
            if switches.contains(&name) {
                if inline.is_some() {
                    return Err(CliError::usage(format!("--{name}: takes no value")));
                }
                if out.switch(name) {
                    return Err(CliError::usage(format!("--{name}: given more than once")));
                }
                out.switches.push(name.to_string());
                continue;
            }
            if !allowed.contains(&name) {
                return Err(unknown(command, arg));
            }
            if out.flags.iter().any(|(n, _)| n == name) {
                return Err(CliError::usage(format!("--{name}: given more than once")));
            }
            let value = match inline {
                Some(v) => v,
                None => it
                    .next()
                    .and_then(|v| v.to_str())
                    .map(str::to_string)
                    .ok_or_else(|| CliError::usage(format!("--{name}: missing value")))?,
            };
            out.flags.push((name.to_string(), value));
        }
        Ok(out)
    }

    /// The value of `--name`, if given.
    pub fn get(&self, name: &str) -> Option<&str> {
        self.flags
            .iter()
            .find(|(n, _)| n == name)
            .map(|(_, v)| v.as_str())
    }

    /// Whether the switch `--name` was given.
    pub fn switch(&self, name: &str) -> bool {
        self.switches.iter().any(|n| n == name)
    }

    /// The value of a required `--name`.
    pub fn required(&self, name: &str) -> Result<&str, CliError> {
        self.get(name)
            .ok_or_else(|| CliError::usage(format!("--{name}: required")))
    }

    /// `--name` as a finite number, if given.
    pub fn number(&self, name: &str) -> Result<Option<f64>, CliError> {
        self.get(name)
            .map(|v| {
                v.trim()
                    .parse::<f64>()
                    .ok()
                    .filter(|x| x.is_finite())
                    .ok_or_else(|| {
                        CliError::usage(format!("--{name}: expected a finite number, got '{v}'"))
                    })
            })
            .transpose()
    }

    /// `--name` as a non-negative integer, if given.
    pub fn integer(&self, name: &str) -> Result<Option<usize>, CliError> {
        self.get(name)
            .map(|v| {
                v.trim().parse::<usize>().map_err(|_| {
                    CliError::usage(format!("--{name}: expected a whole number, got '{v}'"))
                })
            })
            .transpose()
    }

    /// Fails unless there are exactly `n` positional words.
    pub fn expect_positional(&self, command: &str, n: usize, what: &str) -> Result<(), CliError> {
        match self.positional.len() {
            k if k == n => Ok(()),
            0 => Err(CliError::usage(format!("{command}: missing {what}"))),
            _ => Err(CliError::usage(format!(
                "{command}: unexpected argument '{}'",
                self.positional[n.min(self.positional.len() - 1)]
            ))),
        }
    }
}

fn unknown(command: &str, arg: &str) -> CliError {
    CliError::usage(format!(
        "{command}: unknown option '{arg}' (see scatterloc help)"
    ))
}

/// Parses `X,Y` (metres) for the flag `name`.
pub fn parse_xy(name: &str, v: &str) -> Result<[f64; 2], CliError> {
    let bad = || {
        CliError::usage(format!(
            "--{name}: expected X,Y (two numbers in metres), got '{v}'"
        ))
    };
    let (x, y) = v.split_once(',').ok_or_else(bad)?;
    let x: f64 = x.trim().parse().map_err(|_| bad())?;
    let y: f64 = y.trim().parse().map_err(|_| bad())?;
    if x.is_finite() && y.is_finite() {
        Ok([x, y])
    } else {
        Err(bad())
    }
}
