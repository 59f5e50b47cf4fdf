//! `<integrator type="direct">`, as Mitsuba 3's `direct`: `emitter_samples` (strata's light
//! samples, per light group or per one-light choice) and `bsdf_samples` BSDF samples per shading
//! point, both defaulting to `shading_samples` (default 1; Mitsuba refuses `shading_samples`
//! given together with either), combined by the power heuristic (`integrator/direct_bsdf.rs`);
//! `emitter_samples` 0 is BSDF sampling alone, `bsdf_samples` 0 light sampling alone, both 0 is
//! refused; `hide_emitters`.

use super::{Build, Plugin, Run};
use crate::scene::desc::IntegratorKind;
use crate::scene::error::SceneError;
use crate::scene::xml::props::Props;

/// Registry entry.
pub const PLUGIN: Plugin = Plugin { tag: "integrator", kind: "direct", run: Run::Scene(run) };

fn run<'e>(b: &mut Build<'e>, p: &Props<'e>) -> Result<(), SceneError> {
    if p.has("shading_samples") && (p.has("emitter_samples") || p.has("bsdf_samples")) {
        return Err(p
            .elem
            .at
            .err("direct: give either shading_samples or emitter_samples/bsdf_samples, not both (as Mitsuba)"));
    }
    let shading = p.int("shading_samples", 1)?;
    let e = p.int("emitter_samples", shading)?;
    let bs = p.int("bsdf_samples", shading)?;
    let max = i64::from(b.limits.max_light_samples);
    if e < 0 || e > max {
        return Err(p.elem.at.err(format!("emitter_samples {e} must be in 0..={max}")));
    }
    if bs < 0 || bs > max {
        return Err(p.elem.at.err(format!("bsdf_samples {bs} must be in 0..={max}")));
    }
    if e + bs == 0 {
        return Err(p.elem.at.err("direct needs at least one BSDF or emitter sample"));
    }
    b.desc.hide_emitters = p.bool("hide_emitters", false)?;
    b.desc.integrator = IntegratorKind::Direct;
    b.desc.light_samples = e.max(1) as u32;
    b.desc.emitter_sampling = e > 0;
    b.desc.bsdf_samples = bs as u32;
    Ok(())
}

#[cfg(test)]
mod tests {
    use crate::scene::limits::Limits;
    use crate::scene::xml::{load, Loaded};

    /// A one-rectangle scene with `<integrator type="direct">` holding `props`.
    fn direct(props: &str) -> Result<Loaded, crate::scene::error::SceneError> {
        let d = tempfile::tempdir().unwrap();
        let path = d.path().join("s.xml");
        let text = format!(
            "<scene version=\"3.0.0\">\n<integrator type=\"direct\">{props}</integrator>\n<sensor type=\"perspective\"><film type=\"hdrfilm\"><rfilter type=\"box\"/></film></sensor>\n<shape type=\"rectangle\"/>\n</scene>\n"
        );
        std::fs::write(&path, text).unwrap();
        load(&path, &Limits::default(), &[])
    }

    fn samples(l: &Loaded) -> (u32, bool, u32) {
        (l.desc.light_samples, l.desc.emitter_sampling, l.desc.bsdf_samples)
    }

    #[test]
    fn reads_mitsubas_sample_counts() {
        let int = |n: &str, v: u32| format!("<integer name=\"{n}\" value=\"{v}\"/>");
        assert_eq!(samples(&direct("").unwrap()), (1, true, 1), "Mitsuba's defaults: one of each");
        assert_eq!(samples(&direct(&int("shading_samples", 3)).unwrap()), (3, true, 3));
        assert_eq!(samples(&direct(&int("emitter_samples", 2)).unwrap()), (2, true, 1));
        let bsdf_only = direct(&(int("emitter_samples", 0) + &int("bsdf_samples", 4))).unwrap();
        assert_eq!(samples(&bsdf_only), (1, false, 4), "emitter_samples 0: BSDF samples alone");
        assert_eq!(samples(&direct(&int("bsdf_samples", 0)).unwrap()), (1, true, 0));
        let hide = direct("<boolean name=\"hide_emitters\" value=\"true\"/>").unwrap();
        assert!(hide.desc.hide_emitters);
    }

    #[test]
    fn refuses_what_mitsuba_refuses_and_reports_unused_properties() {
        let int = |n: &str, v: i64| format!("<integer name=\"{n}\" value=\"{v}\"/>");
        let err = |props: String| direct(&props).err().expect("refused").to_string();
        let both = err(int("shading_samples", 2) + &int("bsdf_samples", 1));
        assert!(both.contains("shading_samples") && both.contains(":2"), "{both}");
        let none = err(int("emitter_samples", 0) + &int("bsdf_samples", 0));
        assert!(none.contains("at least one BSDF or emitter sample"), "{none}");
        assert!(err(int("bsdf_samples", -1)).contains("bsdf_samples -1"));
        let w = direct(&int("max_depth", 3)).unwrap().warnings;
        assert!(w.iter().any(|w| w.contains("max_depth")), "{w:?}");
    }
}
