//! Progress bars on stderr and Ctrl-C.
//!
//! Ctrl-C sets a flag (through the `ctrlc` crate) instead of killing the process; the
//! simplification loop polls it through [`Observer::should_stop`] every few thousand
//! contractions, and the commands check it between files, so a run stops within a
//! moment, writes no output for the interrupted work (outputs are only ever written
//! whole, through a temporary file and a rename) and exits with 130.
//!
//! Bars are drawn only when stderr is a terminal and `--quiet` is not given; otherwise
//! nothing is drawn, so logs get no escape codes.

use indicatif::{ProgressBar, ProgressStyle};
use qem_mesh::simplify::{Observer, Phase, Progress};
use std::io::IsTerminal;
use std::sync::atomic::{AtomicBool, Ordering};
use std::time::Duration;

/// The exit code of a run stopped by Ctrl-C (128 + SIGINT, the shell convention).
pub const INTERRUPTED_EXIT: u8 = 130;

static INTERRUPTED: AtomicBool = AtomicBool::new(false);

/// Makes Ctrl-C set the interruption flag instead of ending the process. A failure to
/// install the handler is not fatal: Ctrl-C then ends the process the default way,
/// which still leaves no partial output (writes are atomic), only temporary files.
pub fn catch_ctrl_c() {
    let _ = ctrlc::set_handler(|| INTERRUPTED.store(true, Ordering::SeqCst));
}

/// Whether Ctrl-C was pressed.
pub fn interrupted() -> bool {
    INTERRUPTED.load(Ordering::SeqCst)
}

/// Whether to draw bars: stderr is a terminal and the user did not ask for quiet.
pub fn bars_wanted(quiet: bool) -> bool {
    !quiet && std::io::stderr().is_terminal()
}

/// A bar over the contraction loop of one mesh (per mille of the work), hidden unless
/// `visible`; it says `reading…` until the caller's observer names the next stage.
pub fn simplify_bar(visible: bool, name: &str) -> ProgressBar {
    if !visible {
        return ProgressBar::hidden();
    }
    let bar = ProgressBar::new(1000);
    bar.set_style(
        ProgressStyle::with_template("{prefix} [{bar:30}] {percent:>3}% {msg} ({elapsed})")
            .unwrap_or_else(|_| ProgressStyle::default_bar())
            .progress_chars("=> "),
    );
    bar.set_prefix(name.to_string());
    bar.set_message("reading…");
    bar.enable_steady_tick(Duration::from_millis(200));
    bar
}

/// A bar over the files of a batch, hidden unless `visible`.
pub fn batch_bar(visible: bool, files: usize) -> ProgressBar {
    if !visible {
        return ProgressBar::hidden();
    }
    let bar = ProgressBar::new(files as u64);
    bar.set_style(
        ProgressStyle::with_template(
            "[{bar:30}] {pos}/{len} files, {msg} ({elapsed}, about {eta} left)",
        )
        .unwrap_or_else(|_| ProgressStyle::default_bar())
        .progress_chars("=> "),
    );
    bar.enable_steady_tick(Duration::from_millis(200));
    bar
}

/// Feeds the loop's progress to a bar and passes Ctrl-C on as a stop request.
pub struct BarObserver<'a> {
    bar: &'a ProgressBar,
}

impl<'a> BarObserver<'a> {
    /// An observer drawing on `bar` (which may be hidden).
    pub fn new(bar: &'a ProgressBar) -> Self {
        BarObserver { bar }
    }
}

impl Observer for BarObserver<'_> {
    fn progress(&mut self, p: Progress) {
        if self.bar.is_hidden() {
            return;
        }
        self.bar
            .set_position((p.fraction() * 1000.0).round() as u64);
        self.bar
            .set_message(format!("{} → {} triangles", p.triangles, p.target));
    }

    fn should_stop(&mut self) -> bool {
        interrupted()
    }

    /// Each stage is named as it begins (the ones before the loop's first report take a
    /// while on a large mesh, the bar sitting at 0% meanwhile); the loop's progress then
    /// replaces the name.
    fn phase(&mut self, phase: Phase) {
        self.bar.set_message(format!("{}…", phase.name()));
    }

    fn wants_contractions(&self) -> bool {
        false
    }
}

/// Polls Ctrl-C only (for batch workers, whose progress is counted per file).
pub struct CtrlCObserver;

impl Observer for CtrlCObserver {
    fn should_stop(&mut self) -> bool {
        interrupted()
    }

    fn wants_contractions(&self) -> bool {
        false
    }
}
