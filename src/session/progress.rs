//! Progress of a render session on stderr: on a terminal an `indicatif` bar updated as tiles
//! finish (spp done, elapsed wall time, Mrays/s once the first pass has measured it, ETA; or the
//! time budget left), otherwise a plain line every few seconds and at the end; nothing when
//! disabled.

use crate::render::RenderStats;
use indicatif::{ProgressBar, ProgressDrawTarget, ProgressStyle};
use std::sync::atomic::{AtomicBool, AtomicU64, Ordering};
use std::time::{Duration, Instant};

/// How often the bar polls the tiles-done counter during a pass.
const POLL: Duration = Duration::from_millis(100);

/// Progress state over the passes of one session.
pub struct Progress {
    on: bool,
    /// the bar on a terminal (None: plain lines, or disabled)
    bar: Option<ProgressBar>,
    total: u64,
    done: u64,
    session: u64,
    budget: Option<f64>,
    seconds: f64,
    rays: u64,
    tiles: u64,
    last_line: Instant,
}

impl Progress {
    /// Progress over the sample range `target` of which `done` samples are already held, with a
    /// time `budget` (seconds) or not, for an image of `tiles` tiles; `on` false prints nothing.
    pub fn new(on: bool, target: &std::ops::Range<u32>, done: u32, budget: Option<f64>, tiles: u64) -> Self {
        let tty = std::io::IsTerminal::is_terminal(&std::io::stderr());
        let total = target.len() as u64;
        let bar = (on && tty).then(|| {
            let (len, pos) = match budget {
                Some(b) => ((b * 1000.0) as u64, 0),
                None => (total * tiles.max(1), u64::from(done) * tiles.max(1)),
            };
            let template = if budget.is_some() { "[{bar:40}] {msg}" } else { "[{bar:40}] {msg}, ETA {eta}" };
            let style = ProgressStyle::with_template(template).unwrap_or_else(|_| ProgressStyle::default_bar());
            let bar = ProgressBar::with_draw_target(Some(len), ProgressDrawTarget::stderr());
            bar.set_style(style.progress_chars("#>."));
            bar.set_position(pos);
            bar
        });
        Self {
            on,
            bar,
            total,
            done: u64::from(done),
            session: 0,
            budget,
            seconds: 0.0,
            rays: 0,
            tiles: tiles.max(1),
            last_line: Instant::now(),
        }
    }

    /// Seconds per sample per pixel measured so far in this session.
    pub fn secs_per_spp(&self) -> Option<f64> {
        (self.session > 0).then(|| self.seconds / self.session as f64)
    }

    /// The rate, once a pass has measured it.
    fn mrays(&self) -> Option<f64> {
        (self.session > 0 && self.seconds > 0.0).then(|| self.rays as f64 / self.seconds / 1e6)
    }

    /// `done` spp of the target, elapsed wall seconds, the rate once measured (said to come before
    /// the first pass ends), and the budget left.
    fn message(&self, done: u64, elapsed: f64) -> String {
        let rate = self.mrays().map_or("rate after the first pass".to_string(), |m| format!("{m:.2} Mrays/s"));
        match self.budget {
            Some(b) => format!(
                "{done} spp, {} elapsed, {rate}, {:.1} s of {b} s budget left",
                clock(elapsed),
                (b - elapsed).max(0.0)
            ),
            None => format!("{done}/{} spp, {} elapsed, {rate}", self.total, clock(elapsed)),
        }
    }

    /// Runs one pass of `n` samples, `pass` adding to the tiles-done counter it is given; the bar
    /// (if any) follows the counter while the pass runs. `started` is when the session began.
    pub fn watch<R>(&mut self, n: u32, started: Instant, pass: impl FnOnce(&AtomicU64) -> R) -> R {
        let tiles_done = AtomicU64::new(0);
        let Some(bar) = self.bar.clone() else { return pass(&tiles_done) };
        let running = AtomicBool::new(true);
        let (base, tiles, budget) = (self.done * self.tiles, self.tiles, self.budget);
        let this = &*self;
        std::thread::scope(|scope| {
            scope.spawn(|| {
                while running.load(Ordering::Relaxed) {
                    let elapsed = started.elapsed().as_secs_f64();
                    let t = tiles_done.load(Ordering::Relaxed).min(tiles);
                    match budget {
                        Some(b) => bar.set_position((elapsed.min(b) * 1000.0) as u64),
                        None => bar.set_position(base + u64::from(n) * t),
                    }
                    // The spp done so far, counting a pass's finished tiles pro rata.
                    let done = this.done + u64::from(n) * t / tiles;
                    bar.set_message(this.message(done, elapsed));
                    std::thread::sleep(POLL);
                }
            });
            let r = pass(&tiles_done);
            running.store(false, Ordering::Relaxed);
            r
        })
    }

    /// Records a finished pass of `n` samples with its stats, `elapsed` seconds into the session.
    pub fn pass(&mut self, n: u32, st: &RenderStats, elapsed: f64) {
        self.done += u64::from(n);
        self.session += u64::from(n);
        self.seconds += st.seconds;
        self.rays += st.counters.total_rays();
        if !self.on {
            return;
        }
        if let Some(bar) = &self.bar {
            match self.budget {
                Some(b) => bar.set_position((elapsed.min(b) * 1000.0) as u64),
                None => bar.set_position(self.done * self.tiles),
            }
            bar.set_message(self.message(self.done, elapsed));
        } else if self.last_line.elapsed().as_secs_f64() > 5.0 || self.done == self.total {
            let line = match self.budget {
                Some(_) => self.message(self.done, elapsed),
                None => {
                    let eta = self.secs_per_spp().unwrap_or(0.0) * (self.total - self.done) as f64;
                    format!("{}, ETA {eta:.1} s", self.message(self.done, elapsed))
                }
            };
            eprintln!("strata: {line}");
            self.last_line = Instant::now();
        }
    }

    /// Prints a message on stderr above the bar (plainly when there is none).
    pub fn warn(&self, msg: &str) {
        match &self.bar {
            Some(bar) => bar.suspend(|| eprintln!("{msg}")),
            None => eprintln!("{msg}"),
        }
    }

    /// Ends the bar (leaving its last state on the terminal).
    pub fn finish(&self) {
        if let Some(bar) = &self.bar {
            bar.finish();
        }
    }
}

/// Wall time as `12.3 s`, `4 min 05 s` or `2 h 03 min`.
fn clock(seconds: f64) -> String {
    let s = seconds.max(0.0);
    if s < 60.0 {
        format!("{s:.1} s")
    } else if s < 3600.0 {
        format!("{} min {:02} s", (s / 60.0) as u64, (s % 60.0) as u64)
    } else {
        format!("{} h {:02} min", (s / 3600.0) as u64, ((s % 3600.0) / 60.0) as u64)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_rate_shows_only_once_measured_and_elapsed_time_always() {
        let mut p = Progress::new(true, &(0..16), 0, None, 4);
        let first = p.message(0, 0.4);
        assert!(first.contains("0.4 s elapsed") && !first.contains("Mrays/s"), "{first}");
        let mut st = RenderStats { seconds: 2.0, ..Default::default() };
        st.counters.camera = 4_000_000;
        p.pass(1, &st, 2.5);
        let later = p.message(1, 2.5);
        assert!(later.contains("2.5 s elapsed") && later.contains("2.00 Mrays/s"), "{later}");
        assert_eq!(clock(125.0), "2 min 05 s");
        assert_eq!(clock(7380.0), "2 h 03 min");
    }
}
