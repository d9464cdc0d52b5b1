//! The one failure type of the CLI: a message for stderr and the process exit status. A leaf
//! module: `cli` and `cmd` import it, it imports nothing of theirs.

/// A failure to report: one line on stderr and an exit status.
#[derive(Debug)]
pub struct CliError {
    /// The message (a single line).
    pub message: String,
    /// Process exit status.
    pub code: i32,
}

impl CliError {
    /// Bad input: exit status 2.
    pub fn usage(message: impl Into<String>) -> CliError {
        CliError {
            message: message.into(),
            code: 2,
        }
    }

    /// Failure to write results: exit status 1.
    pub fn output(message: impl Into<String>) -> CliError {
        CliError {
            message: message.into(),
            code: 1,
        }
    }
}
