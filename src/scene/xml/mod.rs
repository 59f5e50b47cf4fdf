//! Mitsuba 3 XML scenes: `doc.rs` reads the file (includes, defaults, `$name`, `<path>`, the 0.6
//! upgrade), `values.rs` and `props.rs` read property values, `plugins/` holds one file per plugin
//! and the registry, `shape.rs` places shapes. [`load`] is the entry point.

pub mod doc;
pub mod elem;
pub mod plugins;
pub mod props;
pub mod shape;
pub mod tables;
pub mod upgrade;
pub mod values;

use crate::scene::desc::SceneDesc;
use crate::scene::error::SceneError;
use crate::scene::limits::Limits;
use std::collections::HashMap;
use std::path::Path;

/// A scene path naming a Mitsuba XML file (extension `.xml`, any case).
pub fn is_xml(p: &Path) -> bool {
    p.extension().is_some_and(|e| e.eq_ignore_ascii_case("xml"))
}

/// A loaded scene and the warnings (`file:line: ...`) to print.
pub struct Loaded {
    /// the scene
    pub desc: SceneDesc,
    /// unused properties and approximations, each naming file:line
    pub warnings: Vec<String>,
}

/// Loads the Mitsuba XML scene `path` with the `-D name=value` parameters `defines`.
pub fn load(path: &Path, limits: &Limits, defines: &[(String, String)]) -> Result<Loaded, SceneError> {
    let mut reader = doc::Reader::new(limits, defines);
    let root = reader.read_scene(path)?;
    let mut ids: HashMap<String, doc::Elem> = HashMap::new();
    collect_ids(&root, &mut ids)?;
    let mut b = plugins::Build::new(path.to_path_buf(), &ids, limits, reader.search.clone());
    let mut sensor = false;
    let mut integrator = false;
    for e in &root.children {
        match e.tag.as_str() {
            "sensor" => {
                sensor = true;
                b.run_scene(e)?;
            }
            "integrator" => {
                if integrator {
                    return Err(e.at.err("a second <integrator> is not supported"));
                }
                integrator = true;
                b.run_scene(e)?;
            }
            "shape" => b.shape(e)?,
            "emitter" => {
                if e.attr("type") == Some("area") {
                    return Err(e.at.err("an area emitter must be nested in a <shape>"));
                }
                b.run_scene(e)?
            }
            // Declared for reference (`id`): read where referenced; an unreferenced one is still
            // checked, as Mitsuba instantiates it.
            "bsdf" => {
                b.bsdf(e)?;
            }
            "texture" => {
                b.texture(e)?;
            }
            "medium" | "phase" | "volume" => {
                return Err(e.at.err(format!("<{}> (participating media) is not supported", e.tag)))
            }
            t if props::PROPERTY_TAGS.contains(&t) => {
                return Err(e.at.err(format!("<{t}> is a property; it cannot stand at the top of a scene")))
            }
            t => return Err(e.at.err(format!("unknown element <{t}> in <scene>"))),
        }
    }
    if !sensor {
        return Err(SceneError::new(
            path,
            0,
            "the scene has no <sensor> (strata has no default camera for XML scenes)",
        ));
    }
    if !integrator {
        // Mitsuba's default integrator.
        b.desc.integrator = crate::scene::desc::IntegratorKind::PathTracer;
        b.desc.max_depth = -1;
        b.desc.nee = crate::scene::desc::Nee::Mis;
        b.desc.importance_sampling = crate::scene::desc::ImportanceSampling::Brdf;
        b.desc.russian_roulette = true;
        b.desc.rr_depth = 5;
    }
    // Mitsuba's `diffuse` is black from behind unless wrapped in `twosided`: the course-kind
    // materials the `diffuse` plugin left one-sided are listed, then given the course's flag back.
    let course = crate::bsdf::interface::COURSE;
    for (i, m) in b.desc.materials.iter_mut().enumerate() {
        if m.bsdf.kind == course && !m.bsdf.twosided {
            b.desc.one_sided.push(i as u32);
            m.bsdf.twosided = true;
        }
    }
    Ok(Loaded { desc: b.desc, warnings: b.warnings })
}

/// Every element with an `id` (anywhere), for `<ref>`; a duplicate id is an error.
fn collect_ids(e: &doc::Elem, ids: &mut HashMap<String, doc::Elem>) -> Result<(), SceneError> {
    for c in &e.children {
        if let Some(id) = c.attr("id").filter(|_| c.tag != "ref") {
            if ids.insert(id.to_string(), c.clone()).is_some() {
                return Err(c.at.err(format!("id \"{id}\" is declared twice")));
            }
        }
        collect_ids(c, ids)?;
    }
    Ok(())
}

#[cfg(test)]
#[path = "instance_tests.rs"]
mod instance_tests;
#[cfg(test)]
#[path = "one_sided_tests.rs"]
mod one_sided_tests;
