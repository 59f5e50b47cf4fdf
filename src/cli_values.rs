//! The command line's value parsers (clap's `value_parser`s of `cli.rs`, the binary's grammar):
//! each flag value checked and converted, or refused with what the flag takes ([`ValueError`]).

use crate::sampler::SamplerKind;
use crate::scene::desc::{ImportanceSampling, IntegratorKind, Nee};

/// Why a flag's value was refused (clap prints the message after the flag's name).
#[derive(Debug, thiserror::Error)]
pub enum ValueError {
    /// The value is not of the form the flag takes.
    #[error("expected {expected}, got `{got}`")]
    Expected {
        /// the form the flag takes
        expected: &'static str,
        /// the value given
        got: String,
    },
    /// A name the flag does not know.
    #[error("unknown {what} `{got}` ({known})")]
    Unknown {
        /// what the flag names
        what: &'static str,
        /// the value given
        got: String,
        /// the names it knows
        known: &'static str,
    },
    /// `--clamp` needs a positive finite radiance.
    #[error("--clamp expects a positive finite radiance, got `{0}`")]
    Clamp(String),
    /// A `--limit` assignment the scene limits refuse.
    #[error(transparent)]
    Limit(crate::scene::parse::LimitError),
    /// A sampler name or point-set file that does not resolve.
    #[error(transparent)]
    Sampler(crate::pointset::PointSetError),
}

/// A value not of the form `expected`.
fn expected(expected: &'static str, got: &str) -> ValueError {
    ValueError::Expected { expected, got: got.into() }
}

/// A name `got` that the flag naming `what`s does not know (it knows `known`).
fn unknown(what: &'static str, got: &str, known: &'static str) -> ValueError {
    ValueError::Unknown { what, got: got.into(), known }
}

/// Checks one `--limit NAME=VALUE` (the assignment is applied again in [`limits_of`]).
pub fn parse_limit(s: &str) -> Result<String, ValueError> {
    crate::scene::parse::Limits::default().set(s).map(|()| s.to_string()).map_err(ValueError::Limit)
}

/// The default limits with every (already checked) `--limit` applied in order.
pub fn limits_of(assignments: &[String]) -> crate::scene::parse::Limits {
    let mut limits = crate::scene::parse::Limits::default();
    for a in assignments {
        let _ = limits.set(a); // validated by `parse_limit`
    }
    limits
}

/// `--size WxH`: two positive integers.
pub fn parse_size(s: &str) -> Result<(u32, u32), ValueError> {
    let (w, h) = s.split_once(['x', 'X']).ok_or_else(|| expected("WxH", s))?;
    let p = |v: &str| v.trim().parse::<u32>().map_err(|_| expected("WxH with positive integers", s));
    Ok((p(w)?, p(h)?))
}

/// `--quantize`: truncate or round.
pub fn parse_quantize(s: &str) -> Result<crate::film::Quantize, ValueError> {
    crate::film::Quantize::parse(s).ok_or_else(|| expected("truncate or round", s))
}

/// `--first-sample`: centre (center) or jittered.
pub fn parse_first_sample(s: &str) -> Result<crate::integrator::FirstSample, ValueError> {
    crate::integrator::FirstSample::parse(s).ok_or_else(|| expected("centre or jittered", s))
}

/// `--clamp MAX`: a positive finite radiance.
pub fn parse_clamp(s: &str) -> Result<f32, ValueError> {
    match s.trim().parse::<f32>() {
        Ok(v) if v > 0.0 && v.is_finite() => Ok(v),
        _ => Err(ValueError::Clamp(s.into())),
    }
}

/// `A..B` with A < B (a shard's pixel-sample range).
pub fn parse_range(s: &str) -> Result<(u32, u32), ValueError> {
    let (a, b) = s.split_once("..").ok_or_else(|| expected("A..B", s))?;
    let p = |v: &str| v.trim().parse::<u32>().map_err(|_| expected("A..B with non-negative integers", s));
    let (a, b) = (p(a)?, p(b)?);
    if a >= b {
        return Err(expected("A..B with A < B", s));
    }
    Ok((a, b))
}

/// A registry sampler name, or `file:PATH?options` (the file is loaded and checked here).
pub fn parse_sampler(s: &str) -> Result<SamplerKind, ValueError> {
    crate::pointset::spec::resolve_sampler(s).map_err(ValueError::Sampler)
}

/// `--integrator`: a registry integrator name.
pub fn parse_integrator(s: &str) -> Result<IntegratorKind, ValueError> {
    IntegratorKind::parse(s)
        .ok_or_else(|| unknown("integrator", s, "raytracer, analyticdirect, direct, pathtracer, ptracer"))
}

/// `--nee`: off, on or mis.
pub fn parse_nee(s: &str) -> Result<Nee, ValueError> {
    Nee::parse(s).ok_or_else(|| unknown("next event estimation", s, "off, on, mis"))
}

/// on or off.
pub fn parse_on_off(s: &str) -> Result<bool, ValueError> {
    match s {
        "on" => Ok(true),
        "off" => Ok(false),
        _ => Err(expected("on or off", s)),
    }
}

/// `--importance-sampling`: hemisphere, cosine or brdf.
pub fn parse_importance_sampling(s: &str) -> Result<ImportanceSampling, ValueError> {
    ImportanceSampling::parse(s).ok_or_else(|| unknown("importance sampling", s, "hemisphere, cosine, brdf"))
}

/// `--up`: x, y or z.
pub fn parse_up(s: &str) -> Result<crate::scene::obj::frame::UpAxis, ValueError> {
    crate::scene::obj::frame::UpAxis::parse(s).ok_or_else(|| expected("x, y or z", s))
}

/// `-D NAME=VALUE`: a Mitsuba scene parameter, its name of letters, digits and `_`.
pub fn parse_define(s: &str) -> Result<(String, String), ValueError> {
    let (name, value) = s.split_once('=').ok_or_else(|| expected("NAME=VALUE", s))?;
    let ok = !name.is_empty() && name.chars().all(|c| c.is_ascii_alphanumeric() || c == '_');
    if !ok {
        return Err(expected("a parameter name of letters, digits and _ before =", s));
    }
    Ok((name.to_string(), value.to_string()))
}

/// `--sky`: a radiance `R` or `R,G,B` (or `R G B`) of finite numbers >= 0.
pub fn parse_sky(s: &str) -> Result<glam::Vec3, ValueError> {
    let bad = || expected("a radiance R or R,G,B of finite numbers >= 0", s);
    let v: Vec<f32> = s
        .split([',', ' '])
        .filter(|t| !t.is_empty())
        .map(|t| t.parse::<f32>().map_err(|_| bad()))
        .collect::<Result<_, _>>()?;
    let v = match v.as_slice() {
        [r] => glam::Vec3::splat(*r),
        [r, g, b] => glam::Vec3::new(*r, *g, *b),
        _ => return Err(bad()),
    };
    if v.is_finite() && v.min_element() >= 0.0 {
        Ok(v)
    } else {
        Err(bad())
    }
}

/// A whole number >= 0 (counts, seeds, thread counts: 0 often means "all"), refused with what is
/// allowed when negative or malformed.
pub fn parse_count<T: std::str::FromStr>(s: &str) -> Result<T, ValueError> {
    s.trim().parse::<T>().map_err(|_| expected("a whole number >= 0", s))
}

/// A whole number >= 1 (spp, light samples, sizes), refused with what is allowed otherwise.
pub fn parse_positive<T: std::str::FromStr + PartialOrd + Default>(s: &str) -> Result<T, ValueError> {
    match s.trim().parse::<T>() {
        Ok(v) if v > T::default() => Ok(v),
        _ => Err(expected("a whole number >= 1", s)),
    }
}

/// Seconds of a budget: a positive finite number.
pub fn parse_seconds(s: &str) -> Result<f64, ValueError> {
    match s.trim().parse::<f64>() {
        Ok(v) if v > 0.0 && v.is_finite() => Ok(v),
        _ => Err(expected("a positive number of seconds", s)),
    }
}

/// `--max-depth`: -1 (unbounded) or a depth >= 0 (the upper cap is `--limit max_depth`'s).
pub fn parse_max_depth(s: &str) -> Result<i32, ValueError> {
    match s.trim().parse::<i32>() {
        Ok(v) if v >= -1 => Ok(v),
        _ => Err(expected("-1 (unbounded) or a depth >= 0", s)),
    }
}

/// Seconds between checkpoints: a finite number >= 0.
pub fn parse_interval(s: &str) -> Result<f64, ValueError> {
    match s.trim().parse::<f64>() {
        Ok(v) if v >= 0.0 && v.is_finite() => Ok(v),
        _ => Err(expected("a number of seconds >= 0", s)),
    }
}
