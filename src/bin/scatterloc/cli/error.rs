//! clap's errors as the CLI's one line: the flag (or command) first, then the problem, with
//! clap's did-you-mean suggestion kept in the line (`unexpected argument '--runz' (did you mean
//! '--runs'?)`). Help and version requests are printed to stdout (exit status 0).

use std::ffi::OsString;

use clap::error::{ContextKind, ContextValue, ErrorKind};

use crate::failure::CliError;

/// Prints help or the version (`Ok`: status 0, nothing to run), or turns any other error into a
/// usage error. `argv` (without the program name) tells which subcommand the error belongs to.
pub fn handle(e: clap::Error, cmd: &clap::Command, argv: &[OsString]) -> Result<(), CliError> {
    match e.kind() {
        ErrorKind::DisplayHelp | ErrorKind::DisplayVersion => {
            if std::io::IsTerminal::is_terminal(&std::io::stdout()) {
                // clap's own print keeps the colours of a terminal.
                e.print()
                    .map_err(|io| CliError::output(format!("stdout: {io}")))
            } else {
                crate::stdout::write(e.render().to_string().as_bytes())
            }
        }
        _ => Err(CliError::usage(one_line(&e, cmd, argv))),
    }
}

/// The context value `kind` as strings (empty when absent).
fn strings(e: &clap::Error, kind: ContextKind) -> Vec<String> {
    match e.get(kind) {
        Some(ContextValue::String(s)) => vec![s.clone()],
        Some(ContextValue::Strings(v)) => v.clone(),
        Some(ContextValue::StyledStr(s)) => vec![s.to_string()],
        Some(ContextValue::StyledStrs(v)) => v.iter().map(|s| s.to_string()).collect(),
        _ => Vec::new(),
    }
}

/// The first string of context `kind`.
fn string(e: &clap::Error, kind: ContextKind) -> Option<String> {
    strings(e, kind).into_iter().next()
}

/// `--at <X,Y>` → `--at`; `<NAME>` stays.
fn flag(arg: &str) -> &str {
    if arg.starts_with('-') {
        arg.split([' ', '=']).next().unwrap_or(arg)
    } else {
        arg
    }
}

/// `a, b or c`.
fn either(items: &[String]) -> String {
    match items {
        [] => String::new(),
        [one] => one.clone(),
        [init @ .., last] => format!("{} or {last}", init.join(", ")),
    }
}

/// ` (did you mean 'x'?)` from the suggestion contexts, or empty.
fn suggestion(e: &clap::Error) -> String {
    let mut all = strings(e, ContextKind::SuggestedSubcommand);
    all.extend(strings(e, ContextKind::SuggestedArg));
    all.extend(strings(e, ContextKind::SuggestedValue));
    let tips = strings(e, ContextKind::Suggested);
    match (all.as_slice(), tips.as_slice()) {
        ([], []) => String::new(),
        ([], tips) => format!(" (tip: {})", tips.join("; ")),
        (names, _) => {
            let quoted: Vec<String> = names.iter().map(|n| format!("'{n}'")).collect();
            format!(" (did you mean {}?)", either(&quoted))
        }
    }
}

/// The subcommand path of the command line (`["mtl", "roc"]`, empty for the top level): its
/// leading words that name a subcommand of the one before.
fn command_path(cmd: &clap::Command, argv: &[OsString]) -> Vec<String> {
    let mut path = Vec::new();
    let mut c = cmd;
    for word in argv {
        match word.to_str().and_then(|w| c.find_subcommand(w)) {
            Some(sub) if sub.get_name() != "help" => {
                path.push(sub.get_name().to_string());
                c = sub;
            }
            _ => break,
        }
    }
    path
}

/// The subcommand names of the command at `path` (without `help`, which the top level lists
/// last).
fn subcommands(cmd: &clap::Command, path: &[String]) -> Vec<String> {
    let mut c = cmd;
    for p in path {
        match c.find_subcommand(p) {
            Some(s) => c = s,
            None => break,
        }
    }
    let mut names: Vec<String> = c
        .get_subcommands()
        .filter(|s| !s.is_hide_set() && s.get_name() != "help")
        .map(|s| s.get_name().to_string())
        .collect();
    if path.is_empty() {
        names.push("help".into());
    }
    names
}

/// `mtl: ` for a subcommand's error, empty at the top level.
fn prefix(path: &[String]) -> String {
    if path.is_empty() {
        String::new()
    } else {
        format!("{}: ", path.join(" "))
    }
}

/// One line for a clap error (without the `error: ` the caller adds).
pub fn one_line(e: &clap::Error, cmd: &clap::Command, argv: &[OsString]) -> String {
    let path = command_path(cmd, argv);
    let arg = string(e, ContextKind::InvalidArg).unwrap_or_default();
    let value = string(e, ContextKind::InvalidValue).unwrap_or_default();
    let name = flag(&arg).to_string();
    let line = match e.kind() {
        ErrorKind::UnknownArgument => {
            format!(
                "{}unexpected argument '{arg}'{}",
                prefix(&path),
                suggestion(e)
            )
        }
        ErrorKind::InvalidSubcommand => {
            let sub = string(e, ContextKind::InvalidSubcommand).unwrap_or_default();
            let hint = match suggestion(e) {
                s if s.starts_with(" (did you mean") => s,
                _ => format!(" (expected {})", either(&subcommands(cmd, &path))),
            };
            format!("{}unknown subcommand '{sub}'{hint}", prefix(&path))
        }
        ErrorKind::MissingSubcommand | ErrorKind::DisplayHelpOnMissingArgumentOrSubcommand => {
            format!(
                "{}missing subcommand ({})",
                prefix(&path),
                either(&subcommands(cmd, &path))
            )
        }
        ErrorKind::MissingRequiredArgument => {
            let missing: Vec<String> = strings(e, ContextKind::InvalidArg)
                .iter()
                .map(|a| match a.starts_with('-') {
                    true => format!("{}: required", flag(a)),
                    false => format!("{}missing {a}", prefix(&path)),
                })
                .collect();
            missing.join("; ")
        }
        ErrorKind::ValueValidation => {
            let why = std::error::Error::source(e)
                .map(|s| s.to_string())
                .unwrap_or_else(|| format!("invalid value '{value}'"));
            format!("{name}: {why}")
        }
        ErrorKind::InvalidValue if value.is_empty() => format!("{name}: missing value"),
        ErrorKind::InvalidValue if !arg.starts_with('-') => {
            let valid = either(&strings(e, ContextKind::ValidValue));
            format!("{}'{value}' is not {valid}{}", prefix(&path), suggestion(e))
        }
        ErrorKind::InvalidValue => {
            let valid = either(&strings(e, ContextKind::ValidValue));
            let what = match name.as_str() {
                "--model" => format!("unknown model '{value}' (expected {valid})"),
                "--experiment" => format!("unknown experiment '{value}' (expected {valid})"),
                "--trajectory" => format!("'{value}' is not one of {valid}"),
                _ => format!("'{value}' is not {valid}"),
            };
            let hint = suggestion(e);
            format!("{name}: {what}{hint}")
        }
        ErrorKind::ArgumentConflict => {
            let prior = strings(e, ContextKind::PriorArg);
            if prior.iter().any(|p| flag(p) == name) || prior.is_empty() {
                format!("{name}: given more than once")
            } else {
                let others: Vec<&str> = prior.iter().map(|p| flag(p)).collect();
                format!("{name}: cannot be used with {}", others.join(", "))
            }
        }
        ErrorKind::TooManyValues if arg.starts_with('-') => {
            format!("{name}: takes no value (got '{value}')")
        }
        ErrorKind::TooManyValues => format!("unexpected argument '{value}'"),
        ErrorKind::InvalidUtf8 => "an argument is not valid UTF-8".to_string(),
        _ => fallback(e),
    };
    line.replace(['\n', '\r'], " ")
}

/// Any other error: clap's own text without the usage and help lines, joined into one line.
fn fallback(e: &clap::Error) -> String {
    let text = e.render().to_string();
    let parts: Vec<&str> = text
        .lines()
        .map(str::trim)
        .filter(|l| !l.is_empty() && !l.starts_with("Usage:") && !l.starts_with("For more"))
        .collect();
    parts
        .join(" ")
        .trim_start_matches("error:")
        .trim()
        .to_string()
}
