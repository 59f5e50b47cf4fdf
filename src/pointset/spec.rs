//! Sampler specs naming point sets: `file:PATH` with optional `?key=value&...` options
//! (`scramble=shift|owen|xor|none`, `sets=hash|pixel`, `pad=NAME`, `shuffle=dim|none`), and their registration as a
//! run-time [`SamplerKind`] (see [`crate::sampler::file`] for what the options mean).

use super::{formats, PointSetError, PointSets};
use crate::sampler::file::{self, FileLayout, PointTable, Scramble, SetMap};
use crate::sampler::SamplerKind;
use std::path::PathBuf;

/// How loaded points serve a render: the options of a `file:` spec or of a Python array.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Options {
    /// randomization per (pixel, dimension) (default: Cranley-Patterson shift)
    pub scramble: Scramble,
    /// which set serves a (pixel, dimension) (default: keyed hash)
    pub map: SetMap,
    /// pad a one-coordinate set's second coordinate from this registry layout
    pub pad: Option<SamplerKind>,
    /// shuffle the point index per dimension (default), or keep one index for every dimension
    /// (`shuffle=none`: a deliberate correlation)
    pub shuffle: bool,
}

impl Default for Options {
    fn default() -> Self {
        Self { scramble: Scramble::Shift, map: SetMap::Hash, pad: None, shuffle: true }
    }
}

impl Options {
    /// Applies one `key=value` option.
    pub fn set(&mut self, kv: &str) -> Result<(), PointSetError> {
        let err = |why: String| PointSetError::Spec(format!("option `{kv}`: {why}"));
        let (k, v) = kv.split_once('=').ok_or_else(|| err("expected KEY=VALUE".into()))?;
        match k.trim() {
            "scramble" => {
                self.scramble =
                    Scramble::parse(v.trim()).ok_or_else(|| err("expected shift, owen, xor or none".into()))?
            }
            "sets" => self.map = SetMap::parse(v.trim()).ok_or_else(|| err("expected hash or pixel".into()))?,
            "pad" => {
                self.pad = Some(
                    SamplerKind::parse(v)
                        .ok_or_else(|| err(format!("unknown sampler (registry: {})", SamplerKind::names())))?,
                )
            }
            "shuffle" => {
                self.shuffle = match v.trim() {
                    "dim" => true,
                    "none" => false,
                    _ => return Err(err("expected dim (each dimension its own index order) or none".into())),
                }
            }
            _ => return Err(err("known options: scramble, sets, pad, shuffle".into())),
        }
        Ok(())
    }

    /// The options in spec syntax, only those that differ from the defaults ("" if none).
    pub fn suffix(&self) -> String {
        let d = Self::default();
        let mut kv = Vec::new();
        if self.scramble != d.scramble {
            kv.push(format!("scramble={}", self.scramble.name()));
        }
        if self.map != d.map {
            kv.push(format!("sets={}", self.map.name()));
        }
        if let Some(p) = self.pad {
            kv.push(format!("pad={}", p.name()));
        }
        if !self.shuffle {
            kv.push("shuffle=none".into());
        }
        if kv.is_empty() {
            String::new()
        } else {
            format!("?{}", kv.join("&"))
        }
    }
}

/// A parsed `file:PATH?options` spec.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct SamplerSpec {
    /// the point-set file
    pub path: PathBuf,
    /// its options
    pub options: Options,
}

impl SamplerSpec {
    /// Parses `file:PATH[?key=value&...]`; None if `s` does not start with `file:`.
    pub fn parse(s: &str) -> Option<Result<Self, PointSetError>> {
        let rest = s.trim().strip_prefix("file:")?;
        let (path, opts) = rest.split_once('?').unwrap_or((rest, ""));
        if path.is_empty() {
            return Some(Err(PointSetError::Spec(format!("`{s}`: expected file:PATH"))));
        }
        let mut options = Options::default();
        for kv in opts.split('&').filter(|kv| !kv.is_empty()) {
            if let Err(e) = options.set(kv) {
                return Some(Err(e));
            }
        }
        Some(Ok(Self { path: PathBuf::from(path), options }))
    }

    /// Loads, checks and registers the file's points.
    pub fn load(&self) -> Result<SamplerKind, PointSetError> {
        let ps = formats::read(&self.path)?;
        sampler_from_sets(&ps, &format!("file:{}", self.path.display()), self.options)
    }
}

/// A sampler name of the registry or a `file:PATH?options` spec, resolved to its kind (a file is
/// loaded and checked); the error lists the registry's names for an unknown one.
pub fn resolve_sampler(s: &str) -> Result<SamplerKind, PointSetError> {
    if let Some(kind) = file::loaded_named(s.trim()) {
        return Ok(kind); // a point array registered by name (the Python module's `array:NAME:DIGEST`)
    }
    match SamplerSpec::parse(s) {
        Some(spec) => spec?.load(),
        None => SamplerKind::parse(s).ok_or_else(|| {
            PointSetError::Spec(format!(
                "unknown sampler `{s}` ({}, or file:PATH for a point-set file)",
                SamplerKind::names()
            ))
        }),
    }
}

/// Registers checked point sets as a sampler kind named `name` + the non-default options. Sets
/// need two coordinates per point (the first two are used), or one with `pad`.
pub fn sampler_from_sets(ps: &PointSets, name: &str, options: Options) -> Result<SamplerKind, PointSetError> {
    if ps.dims < 2 && options.pad.is_none() {
        return Err(PointSetError::Format {
            source_name: ps.source.clone(),
            why: format!(
                "{} coordinate per point; a sampler dimension takes 2 (add ?pad=sobol to draw the second from a \
                 registry layout)",
                ps.dims
            ),
        });
    }
    let xy = (0..ps.sets * ps.points)
        .map(|i| {
            let c = &ps.data[i * ps.dims..];
            [file::fixed24(c[0]), if ps.dims > 1 { file::fixed24(c[1]) } else { 0 }]
        })
        .collect();
    let too_big = || PointSetError::Format { source_name: ps.source.clone(), why: "too many points".into() };
    let (sets, points) =
        (u32::try_from(ps.sets).map_err(|_| too_big())?, u32::try_from(ps.points).map_err(|_| too_big())?);
    let table = PointTable::new(sets, points, xy).ok_or_else(too_big)?;
    let layout = FileLayout {
        table,
        map: options.map,
        scramble: options.scramble,
        pad: options.pad,
        shuffle: options.shuffle,
        progressive: super::analysis::progressiveness(&ps.sets_2d(4)).progressive,
    };
    Ok(file::register(&format!("{name}{}", options.suffix()), &ps.digest, layout)?)
}
