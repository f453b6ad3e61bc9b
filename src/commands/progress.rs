//! A progress bar for the long headless commands (`run`, `soak`, `bench`): work done, its
//! rate and the time left, drawn on stderr, and only when stderr is a terminal, so piped
//! output and `--json` stay exactly as they are; `--quiet` silences it. `indicatif` draws it.
//! Also [`print_out`], how the commands write their results to stdout: a reader that has
//! gone (`ballpit run ... | head`) ends the printing, not the command; a full disk is an
//! error.

use std::io::IsTerminal;

use indicatif::{ProgressBar, ProgressDrawTarget, ProgressStyle};

/// Writes `text` to stdout. A closed pipe is not an error of the command (what it writes
/// to files, a dump or a series, still gets written); any other failure (a full disk) is.
pub fn print_out(text: &str) -> std::io::Result<()> {
    use std::io::Write;
    let mut out = std::io::stdout().lock();
    match out.write_all(text.as_bytes()).and_then(|()| out.flush()) {
        Err(error) if error.kind() == std::io::ErrorKind::BrokenPipe => Ok(()),
        other => other,
    }
}

/// The bar, or nothing when it is not shown.
pub struct Progress(Option<ProgressBar>);

impl Progress {
    /// A bar for `total` units of work (`unit` names them, e.g. "steps"), shown unless
    /// `quiet` or stderr is not a terminal.
    pub fn new(total: u64, unit: &str, quiet: bool) -> Self {
        Self::shown_if(!quiet && std::io::stderr().is_terminal(), total, unit)
    }

    /// No bar at all.
    pub fn hidden() -> Self {
        Progress(None)
    }

    fn shown_if(shown: bool, total: u64, unit: &str) -> Self {
        if !shown {
            return Self::hidden();
        }
        let template = format!("[{{bar:32}}] {{pos}}/{{len}} {unit}, {{per_sec}}, {{eta}} left");
        let style = ProgressStyle::with_template(&template)
            .unwrap_or_else(|_| ProgressStyle::default_bar())
            .progress_chars("=> ");
        let bar = ProgressBar::with_draw_target(Some(total), ProgressDrawTarget::stderr());
        bar.set_style(style);
        Progress(Some(bar))
    }

    /// Whether a bar is drawn.
    pub fn is_shown(&self) -> bool {
        self.0.is_some()
    }

    /// `done` more units are done.
    pub fn advance(&self, done: u64) {
        if let Some(bar) = &self.0 {
            bar.inc(done);
        }
    }

    /// Runs `print` with the bar out of the way (lines printed meanwhile stay readable).
    pub fn suspend<T>(&self, print: impl FnOnce() -> T) -> T {
        match &self.0 {
            Some(bar) => bar.suspend(print),
            None => print(),
        }
    }
}

impl Drop for Progress {
    /// The bar is cleared when the work ends, leaving the output as it would be without it.
    fn drop(&mut self) {
        if let Some(bar) = &self.0 {
            bar.finish_and_clear();
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_quiet_or_piped_bar_is_not_drawn_and_a_shown_one_counts() {
        assert!(!Progress::new(10, "steps", true).is_shown());
        // Under `cargo test` stderr is captured, not a terminal.
        assert!(!Progress::new(10, "steps", false).is_shown());
        let hidden = Progress::hidden();
        hidden.advance(3);
        assert_eq!(hidden.suspend(|| 7), 7);
        let shown = Progress::shown_if(true, 10, "steps");
        shown.advance(4);
        assert_eq!(shown.0.as_ref().map(ProgressBar::position), Some(4));
    }
}
