//! How a command ends when it does not succeed, and the exit code of each case.

use crate::progress::INTERRUPTED_EXIT;
use std::io::{ErrorKind, Write};
use std::process::ExitCode;

/// Writes `text` to standard output. A reader that closed the pipe early (`qem measure
/// --json | head`) has taken what it wanted: that ends the output quietly, where
/// `print!` would panic. Any other failure to write is an error.
pub fn print_stdout(text: &str) -> Result<(), String> {
    let mut out = std::io::stdout().lock();
    match out.write_all(text.as_bytes()).and_then(|()| out.flush()) {
        Err(e) if e.kind() != ErrorKind::BrokenPipe => {
            Err(format!("cannot write to standard output: {e}"))
        }
        _ => Ok(()),
    }
}

/// Why a command did not succeed.
#[derive(Debug)]
pub enum Failure {
    /// The arguments do not make sense together (exit 2, like the parser's errors).
    Usage(String),
    /// The work failed; the message is one line naming the file (exit 1).
    Failed(String),
    /// Some work failed and has been reported already, line by line (exit 1).
    Reported,
    /// Ctrl-C stopped the run (exit 130).
    Interrupted,
}

impl Failure {
    /// Prints the message, if any, as one line on stderr and gives the exit code.
    pub fn exit(self) -> ExitCode {
        match self {
            Failure::Usage(m) => {
                eprintln!("qem: error: {m}");
                ExitCode::from(2)
            }
            Failure::Failed(m) => {
                eprintln!("qem: error: {m}");
                ExitCode::from(1)
            }
            Failure::Reported => ExitCode::from(1),
            Failure::Interrupted => {
                eprintln!("qem: interrupted; no partial output was written");
                ExitCode::from(INTERRUPTED_EXIT)
            }
        }
    }
}
