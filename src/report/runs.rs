//! Statistics of K runs of a technique against a reference with known per-pixel variance (the
//! seed experiments of `strata experiments`), and their Markdown tables.

use crate::film;
use serde::Serialize;
use std::fmt::Write as _;

/// Error statistics of K runs of one variant against a reference with known per-pixel variance.
#[derive(Clone, Debug, Serialize)]
pub struct Stats {
    /// K
    pub runs: usize,
    /// mean seconds of one run
    pub seconds: f64,
    /// spp of one run
    pub spp: u32,
    /// mean over pixels and channels of the across-run variance (linear radiance)
    pub variance: f64,
    /// the same on the 8-bit gamma-encoded values 0..255 (what a PNG shows)
    pub variance_8bit: f64,
    /// mean over runs of the MSE against the reference (linear)
    pub mse: f64,
    /// the same in 8-bit units
    pub mse_8bit: f64,
    /// mean signed error of the mean image (linear)
    pub bias: f64,
    /// standard error of `bias`: the spread of the runs' mean errors and the reference's own noise
    pub bias_se: f64,
    /// `bias / bias_se`
    pub z: f64,
    /// root of the mean squared per-pixel bias, noise removed (`sqrt(max(0, mean (m-r)^2 - var/K - var_ref))`), linear
    pub rms_bias: f64,
    /// `mean (m - r)^2 / mean (s^2/K + var_ref)`: about 1 for an unbiased technique
    pub bias_ratio: f64,
    /// 1 / (MSE x seconds)
    pub efficiency: f64,
}

/// Per-pixel-channel statistics of `runs` against `reference` whose per-value variance is `ref_var`.
pub fn stats(
    runs: &[Vec<[f32; 3]>],
    reference: &[[f32; 3]],
    ref_var: &[[f32; 3]],
    gamma: f32,
    seconds: f64,
    spp: u32,
) -> Stats {
    let k = runs.len() as f64;
    let m = 3.0 * reference.len() as f64;
    let q = |v: f32| f64::from(film::to_u8(v, gamma));
    let (mut var, mut var8, mut mse, mut mse8, mut err, mut sq, mut den, mut refv) =
        (0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0);
    let mut run_err = vec![0.0f64; runs.len()];
    for (i, px) in reference.iter().enumerate() {
        for c in 0..3 {
            let r = f64::from(px[c]);
            let r8 = q(px[c]);
            let vals = runs.iter().map(|run| f64::from(run[i][c]));
            let mean = vals.clone().sum::<f64>() / k;
            let mean8 = runs.iter().map(|run| q(run[i][c])).sum::<f64>() / k;
            let s2 = vals.clone().map(|v| (v - mean).powi(2)).sum::<f64>() / (k - 1.0);
            var += s2;
            var8 += runs.iter().map(|run| (q(run[i][c]) - mean8).powi(2)).sum::<f64>() / (k - 1.0);
            mse += vals.clone().map(|v| (v - r).powi(2)).sum::<f64>() / k;
            mse8 += runs.iter().map(|run| (q(run[i][c]) - r8).powi(2)).sum::<f64>() / k;
            for (e, run) in run_err.iter_mut().zip(runs) {
                *e += f64::from(run[i][c]) - r;
            }
            err += mean - r;
            sq += (mean - r).powi(2);
            let rv = f64::from(ref_var[i][c]);
            den += s2 / k + rv;
            refv += rv;
        }
    }
    let bias = err / m;
    let run_err: Vec<f64> = run_err.iter().map(|e| e / m).collect();
    let spread = run_err.iter().map(|e| (e - bias).powi(2)).sum::<f64>() / (k - 1.0);
    // Pixels' reference errors are independent: the variance of their mean is sum var / M^2.
    let bias_se = (spread / k + refv / (m * m)).sqrt();
    let (mse, var) = (mse / m, var / m);
    Stats {
        runs: runs.len(),
        seconds,
        spp,
        variance: var,
        variance_8bit: var8 / m,
        mse,
        mse_8bit: mse8 / m,
        bias,
        bias_se,
        z: if bias_se > 0.0 {
            bias / bias_se
        } else if bias == 0.0 {
            0.0
        } else {
            f64::INFINITY.copysign(bias)
        },
        rms_bias: ((sq - den) / m).max(0.0).sqrt(),
        bias_ratio: if den > 0.0 { sq / den } else { f64::INFINITY },
        efficiency: super::efficiency(mse, seconds).unwrap_or(f64::NAN),
    }
}

/// One row of a results table.
#[derive(Clone, Debug, Serialize)]
pub struct Row {
    /// experiment (table) name
    pub table: String,
    /// scene name
    pub scene: String,
    /// technique label
    pub variant: String,
    /// "equal spp", "equal time" or a light-sample count
    pub setting: String,
    /// the statistics
    pub stats: Stats,
}

/// A number in 3 decimals when it reads well so, else in scientific notation with 2.
pub fn g3(x: f64) -> String {
    if x == 0.0 {
        "0".into()
    } else if x.is_finite() && (1e-2..1e4).contains(&x.abs()) {
        format!("{x:.3}")
    } else {
        format!("{x:.2e}")
    }
}

/// Markdown tables of `rows` (K = `runs`, images `width` wide, sheets downsampled by
/// `sheet_factor`), one per (table, scene, setting group), with ratios to the first row.
pub fn markdown(rows: &[Row], runs: usize, width: u32, sheet_factor: u32) -> String {
    let mut md = String::new();
    let _ = writeln!(
        md,
        "# Seed experiments (generated)\n\nRegenerate with `strata experiments` (see docs/experiments/README.md). K = {} runs per \
         variant, images {} pixels wide. `var` is the across-run variance of a pixel value (mean over pixels and channels) in \
         linear radiance, `var8` the same on the 8-bit gamma-encoded values 0..255; `MSE` against the reference (linear), `MSE8` the same in 8-bit units; `bias` \
         the mean signed error with its standard error `se` (runs' spread plus the reference's own noise) and `z = bias/se`; \
         `rms bias` the root mean squared per-pixel bias with the noise removed; `b-ratio = mean (m-r)^2 / mean (s^2/K + \
         var_ref)`, about 1 when unbiased; `eff = 1/(MSE x s)`; ratios are to the first row of each block. Seconds are wall \
         clock on a shared machine.\n",
        runs, width
    );
    let (mut i, mut shown) = (0, Vec::<String>::new());
    while i < rows.len() {
        let r0 = &rows[i];
        let group = |r: &Row| (r.table.clone(), r.scene.clone(), r.setting.clone());
        let g0 = group(r0);
        let mut j = i;
        while j < rows.len() && group(&rows[j]) == g0 {
            j += 1;
        }
        let (head, sheet) = if r0.table == "direct" {
            (
                format!("## Direct lighting, hw2 {}, {} light samples", r0.scene, r0.setting),
                format!("direct-{}.png", r0.scene),
            )
        } else {
            (format!("## {} `{}`, {}", r0.scene, r0.table, r0.setting), format!("path-{}.png", r0.table))
        };
        let _ = writeln!(md, "{head}\n");
        if !shown.contains(&sheet) {
            let caption = if r0.table == "direct" {
                "Tiles: the reference, then run 1 of random, stratified, grid-center, halton; top row 9, bottom row 25 light \
                 samples (`v8` = var8, `rb` = rms bias)."
            } else {
                "Tiles: the reference, then run 1 of each technique at equal spp, then the faster one at equal time."
            };
            let _ = writeln!(
                md,
                "![{sheet}]({sheet})\n\n{caption} Images box-downsampled by {} for the sheet.\n",
                sheet_factor
            );
            shown.push(sheet);
        }
        let _ = writeln!(md, "| variant | spp | s | var | var8 | var ratio | MSE | MSE8 | bias | se | z | rms bias | b-ratio | eff | eff ratio |");
        let _ = writeln!(md, "|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|");
        let first = &rows[i].stats;
        for r in &rows[i..j] {
            let s = &r.stats;
            let _ = writeln!(
                md,
                "| {} | {} | {} | {} | {} | {} | {} | {} | {} | {} | {:.2} | {} | {} | {} | {} |",
                r.variant,
                s.spp,
                g3(s.seconds),
                g3(s.variance),
                g3(s.variance_8bit),
                g3(s.variance / first.variance),
                g3(s.mse),
                g3(s.mse_8bit),
                g3(s.bias),
                g3(s.bias_se),
                s.z,
                g3(s.rms_bias),
                g3(s.bias_ratio),
                g3(s.efficiency),
                g3(s.efficiency / first.efficiency),
            );
        }
        let _ = writeln!(md);
        i = j;
    }
    md
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn stats_of_synthetic_runs_have_the_known_answers() {
        let r = vec![[0.25f32, 0.5, 0.75]; 6];
        let zero = vec![[0.0f32; 3]; 6];
        // Two runs at r - d and r + d: no bias, per-value variance 2 d^2, MSE d^2.
        let d = 0.125f32;
        let runs: Vec<Vec<[f32; 3]>> =
            vec![r.iter().map(|p| p.map(|v| v - d)).collect(), r.iter().map(|p| p.map(|v| v + d)).collect()];
        let s = stats(&runs, &r, &zero, 1.0, 2.0, 4);
        assert_eq!((s.runs, s.spp), (2, 4));
        assert!((s.variance - 2.0 * f64::from(d * d)).abs() < 1e-12, "{}", s.variance);
        assert!((s.mse - f64::from(d * d)).abs() < 1e-12);
        assert_eq!((s.bias, s.z, s.rms_bias), (0.0, 0.0, 0.0));
        assert!((s.efficiency - 1.0 / (2.0 * f64::from(d * d))).abs() < 1e-9);
        // 8-bit (gamma 1, x 255, rounded): 0.125/0.375 -> 32/96, 0.375/0.625 -> 96/159,
        // 0.625/0.875 -> 159/223; variance (a - b)^2 / 2 per channel.
        let want = (64.0f64.powi(2) + 63.0f64.powi(2) + 64.0f64.powi(2)) / 2.0 / 3.0;
        assert!((s.variance_8bit - want).abs() < 1e-9, "{} vs {want}", s.variance_8bit);
        // Identical runs offset by b: zero variance, all error is bias, z infinite.
        let b = 0.0625f32;
        let off: Vec<[f32; 3]> = r.iter().map(|p| p.map(|v| v + b)).collect();
        let s = stats(&[off.clone(), off.clone(), off], &r, &zero, 1.0, 1.0, 1);
        assert_eq!(s.variance, 0.0);
        assert!((s.bias - f64::from(b)).abs() < 1e-12 && (s.rms_bias - f64::from(b)).abs() < 1e-9);
        assert_eq!(s.z, f64::INFINITY);
        // The reference's own variance enters the standard error: M = 18 values of variance v
        // give a mean with variance v / 18.
        let v = 0.02f32;
        let noisy = vec![[v; 3]; 6];
        let runs: Vec<Vec<[f32; 3]>> = vec![r.clone(), r.clone()];
        let s = stats(&runs, &r, &noisy, 1.0, 1.0, 1);
        assert!((s.bias_se - (f64::from(v) / 18.0).sqrt()).abs() < 1e-9, "{}", s.bias_se);
        assert!(s.bias_ratio < 1e-12, "no error at all: ratio 0");
    }
}
