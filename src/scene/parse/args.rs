//! One command line's arguments: counting, numbers, integers in a range and keywords, each with the
//! parser's error message.

use super::LineError;
use crate::scene::limits::limit_hint;

/// Most arguments any command takes (`quadLight`).
const MAX_ARGS: usize = 12;

/// A token for an error message, shortened so a huge token cannot flood the output.
pub(super) fn show(token: &str) -> String {
    match token.char_indices().nth(40) {
        Some((cut, _)) => format!("{}...", &token[..cut]),
        None => token.to_string(),
    }
}

/// How to raise a limit (see [`limit_hint`]).
pub(super) fn hint(field: &str) -> String {
    limit_hint(field)
}

/// One command line split into its command and arguments.
pub(super) struct Args<'a> {
    pub(super) cmd: &'a str,
    tokens: [&'a str; MAX_ARGS],
    /// Number of arguments on the line (may exceed `MAX_ARGS`; only the first ones are kept).
    pub(super) len: usize,
}

impl<'a> Args<'a> {
    pub(super) fn new(cmd: &'a str, rest: impl Iterator<Item = &'a str>) -> Self {
        let mut args = Args { cmd, tokens: [""; MAX_ARGS], len: 0 };
        for token in rest {
            if let Some(slot) = args.tokens.get_mut(args.len) {
                *slot = token;
            }
            args.len += 1;
        }
        args
    }

    pub(super) fn token(&self, i: usize) -> &'a str {
        self.tokens.get(i).copied().unwrap_or_default()
    }

    /// Checks that there are exactly `n` arguments; `what` is the singular noun for one of them.
    pub(super) fn expect(&self, n: usize, what: &str) -> Result<(), LineError> {
        if self.len == n {
            return Ok(());
        }
        let s = if n == 1 { "" } else { "s" };
        Err(format!("{} expects {n} {what}{s}, got {}", self.cmd, self.len).into())
    }

    /// Exactly `N` finite numbers.
    pub(super) fn floats<const N: usize>(&self) -> Result<[f32; N], LineError> {
        self.expect(N, "number")?;
        let mut out = [0.0; N];
        for (i, slot) in out.iter_mut().enumerate() {
            let token = self.token(i);
            let value: f32 = token
                .parse()
                .map_err(|_| format!("{} argument {}: expected a number, got '{}'", self.cmd, i + 1, show(token)))?;
            if !value.is_finite() {
                return Err(format!("{} argument {}: '{}' is not a finite number", self.cmd, i + 1, show(token)).into());
            }
            *slot = value;
        }
        Ok(out)
    }

    /// Exactly `N` integers (written as integers or as integral floats such as `2.0` or `1e3`).
    pub(super) fn ints<const N: usize>(&self) -> Result<[i64; N], LineError> {
        self.expect(N, "integer")?;
        let mut out = [0; N];
        for (i, slot) in out.iter_mut().enumerate() {
            let token = self.token(i);
            let integral = |v: &f64| v.fract() == 0.0 && v.abs() <= 9.0e15;
            let value =
                token.parse::<i64>().ok().or_else(|| token.parse::<f64>().ok().filter(integral).map(|v| v as i64));
            *slot = value.ok_or_else(|| {
                format!("{} argument {}: expected an integer, got '{}'", self.cmd, i + 1, show(token))
            })?;
        }
        Ok(out)
    }

    /// One integer in `min..=max`; `limit` names the `Limits` field that sets `max`.
    pub(super) fn int_in(&self, min: i64, max: i64, limit: &str) -> Result<i64, LineError> {
        let [v] = self.ints()?;
        if v < min {
            Err(format!("{} must be at least {min}, got {v}", self.cmd).into())
        } else if v > max {
            Err(format!("{} {v} exceeds the limit of {max} ({})", self.cmd, hint(limit)).into())
        } else {
            Ok(v)
        }
    }

    /// One keyword out of `options` (ASCII case-insensitive).
    pub(super) fn keyword<T: Copy>(&self, options: &[(&str, T)]) -> Result<T, LineError> {
        let token = self.token(0);
        match options.iter().find(|(name, _)| name.eq_ignore_ascii_case(token)) {
            Some(&(_, value)) if self.len == 1 => Ok(value),
            _ => {
                let names: Vec<&str> = options.iter().map(|(name, _)| *name).collect();
                let got = if self.len == 1 { format!("'{}'", show(token)) } else { format!("{} arguments", self.len) };
                Err(format!("{} expects one of {}, got {got}", self.cmd, names.join("|")).into())
            }
        }
    }
}
