//! Progress of `strata compare` and `strata experiments` on stderr: runs done of the total and the
//! time left at the rate so far; on a terminal one line redrawn in place, otherwise (a log, CI) a
//! plain line per run.

use std::io::{IsTerminal, Write};
use std::time::Instant;

/// Counts runs done against a total and prints them with an ETA.
pub struct Progress {
    on: bool,
    tty: bool,
    total: usize,
    done: usize,
    start: Instant,
    prefix: &'static str,
}

impl Progress {
    /// Progress over `total` runs, printed with `prefix` (`compare`, `experiments`); `on` false
    /// prints nothing.
    pub fn new(prefix: &'static str, total: usize, on: bool) -> Self {
        Progress { on, tty: std::io::stderr().is_terminal(), total, done: 0, start: Instant::now(), prefix }
    }

    /// Adds `n` more runs to the total (work discovered on the way, e.g. an equal-time step).
    pub fn add(&mut self, n: usize) {
        self.total += n;
    }

    /// One run of `what` is done.
    pub fn run_done(&mut self, what: &str) {
        self.done += 1;
        if !self.on {
            return;
        }
        let line = self.line(what);
        let mut err = std::io::stderr().lock();
        let _ = if self.tty {
            let end = if self.done >= self.total { "\n" } else { "" };
            write!(err, "\r\x1b[2K{line}{end}")
        } else {
            writeln!(err, "{line}")
        };
        let _ = err.flush();
    }

    /// The status line after a run: `PREFIX: run D/T (what), E s elapsed, ETA S s`.
    pub fn line(&self, what: &str) -> String {
        let elapsed = self.start.elapsed().as_secs_f64();
        let left = self.total.saturating_sub(self.done);
        let eta = if self.done > 0 { elapsed / self.done as f64 * left as f64 } else { f64::NAN };
        format!(
            "{}: run {}/{} ({what}), {:.1} s elapsed, ETA {}",
            self.prefix,
            self.done,
            self.total,
            elapsed,
            eta_text(eta)
        )
    }
}

/// Seconds as `12 s`, `3 min 20 s` or `?` when unknown.
fn eta_text(s: f64) -> String {
    if !s.is_finite() {
        "?".into()
    } else if s < 60.0 {
        format!("{s:.0} s")
    } else {
        format!("{} min {:.0} s", (s / 60.0).floor(), s % 60.0)
    }
}
