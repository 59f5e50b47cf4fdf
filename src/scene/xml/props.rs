//! `Props`: one plugin's properties (its child elements, `<ref>`s resolved), each recording
//! whether the plugin read it, so that the ones it did not read become warnings naming file:line.

use super::doc::Elem;
use super::values;
use crate::scene::error::SceneError;
use glam::{Mat4, Vec3};
use std::cell::Cell;
use std::collections::HashMap;

/// The object tags a plugin may nest (unnamed or named) besides its properties.
pub const OBJECT_TAGS: &[&str] = &[
    "bsdf",
    "emitter",
    "shape",
    "texture",
    "sensor",
    "film",
    "rfilter",
    "sampler",
    "integrator",
    "medium",
    "phase",
    "volume",
    "spectrum_object",
];

/// A property tag: `float`, `integer`, `boolean`, `string`, `rgb`, `spectrum`, `point`,
/// `vector`, `transform`.
pub const PROPERTY_TAGS: &[&str] =
    &["float", "integer", "boolean", "string", "rgb", "spectrum", "point", "vector", "transform"];

/// A colour property: a constant or a nested texture.
#[derive(Clone, Debug)]
pub enum Color<'e> {
    /// a constant linear-sRGB value
    Rgb(Vec3),
    /// a `<texture>` element (reference resolved)
    Texture(&'e Elem),
}

struct Item<'e> {
    name: Option<String>,
    e: &'e Elem,
    used: Cell<bool>,
}

/// One plugin's properties.
pub struct Props<'e> {
    /// the plugin's element
    pub elem: &'e Elem,
    items: Vec<Item<'e>>,
}

impl<'e> Props<'e> {
    /// The properties of `elem`, `<ref id>` looked up in `ids`; a property named twice is an error.
    pub fn new(elem: &'e Elem, ids: &'e HashMap<String, Elem>) -> Result<Self, SceneError> {
        let mut items: Vec<Item<'e>> = Vec::with_capacity(elem.children.len());
        for c in &elem.children {
            let (name, e) = if c.tag == "ref" {
                let id = c.need("id")?;
                let e = ids.get(id).ok_or_else(|| {
                    c.at.err(format!("<ref id=\"{id}\">: no object has this id (ids are declared before use)"))
                })?;
                (c.attr("name").map(str::to_string), e)
            } else {
                (c.attr("name").map(str::to_string), c)
            };
            if PROPERTY_TAGS.contains(&c.tag.as_str()) && name.is_none() {
                return Err(c.at.err(format!("<{}> needs a `name` attribute", c.tag)));
            }
            if !PROPERTY_TAGS.contains(&e.tag.as_str()) && !OBJECT_TAGS.contains(&e.tag.as_str()) {
                return Err(c.at.err(format!("unknown element <{}> inside {}", e.tag, elem.what())));
            }
            if let Some(n) = &name {
                if items.iter().any(|i| i.name.as_deref() == Some(n)) {
                    return Err(c.at.err(format!("property \"{n}\" of {} is given twice", elem.what())));
                }
            }
            items.push(Item { name, e, used: Cell::new(false) });
        }
        Ok(Self { elem, items })
    }

    fn find(&self, name: &str) -> Option<&Item<'e>> {
        let it = self.items.iter().find(|i| i.name.as_deref() == Some(name))?;
        it.used.set(true);
        Some(it)
    }

    /// The element of property `name` (marked read), if given.
    pub fn get(&self, name: &str) -> Option<&'e Elem> {
        self.find(name).map(|i| i.e)
    }

    /// Whether property `name` is given (does not mark it read).
    pub fn has(&self, name: &str) -> bool {
        self.items.iter().any(|i| i.name.as_deref() == Some(name))
    }

    fn expect(&self, e: &Elem, name: &str, tags: &[&str]) -> Result<(), SceneError> {
        if tags.contains(&e.tag.as_str()) {
            Ok(())
        } else {
            Err(e.at.err(format!(
                "property \"{name}\" of {} must be <{}>, not <{}>",
                self.elem.what(),
                tags.join("> or <"),
                e.tag
            )))
        }
    }

    /// Float property `name` (`<float>` or `<integer>`), `default` when absent.
    pub fn float(&self, name: &str, default: f32) -> Result<f32, SceneError> {
        let Some(e) = self.get(name) else { return Ok(default) };
        self.expect(e, name, &["float", "integer"])?;
        values::float(e, e.need("value")?)
    }

    /// Integer property `name`, `default` when absent.
    pub fn int(&self, name: &str, default: i64) -> Result<i64, SceneError> {
        let Some(e) = self.get(name) else { return Ok(default) };
        self.expect(e, name, &["integer"])?;
        values::integer(e, e.need("value")?)
    }

    /// Boolean property `name`, `default` when absent.
    pub fn bool(&self, name: &str, default: bool) -> Result<bool, SceneError> {
        let Some(e) = self.get(name) else { return Ok(default) };
        self.expect(e, name, &["boolean"])?;
        values::boolean(e, e.need("value")?)
    }

    /// String property `name`, if given.
    pub fn string(&self, name: &str) -> Result<Option<&'e str>, SceneError> {
        let Some(e) = self.get(name) else { return Ok(None) };
        self.expect(e, name, &["string"])?;
        e.need("value").map(Some)
    }

    /// Point or vector property `name`, if given.
    pub fn vec3(&self, name: &str) -> Result<Option<Vec3>, SceneError> {
        let Some(e) = self.get(name) else { return Ok(None) };
        self.expect(e, name, &["point", "vector"])?;
        values::vec3(e, 0.0, false).map(Some)
    }

    /// Transform property `name` (identity when absent).
    pub fn transform(&self, name: &str) -> Result<Mat4, SceneError> {
        let Some(e) = self.get(name) else { return Ok(Mat4::IDENTITY) };
        self.expect(e, name, &["transform"])?;
        values::transform(e)
    }

    /// Colour property `name`: `rgb`, `spectrum`, `float` (grey) or a `texture`; `in_emitter`
    /// selects Mitsuba's conversion of spectra for emitters.
    pub fn color(&self, name: &str, in_emitter: bool) -> Result<Option<Color<'e>>, SceneError> {
        let Some(e) = self.get(name) else { return Ok(None) };
        self.expect(e, name, &["rgb", "spectrum", "float", "texture"])?;
        Ok(Some(match e.tag.as_str() {
            "rgb" => Color::Rgb(values::rgb(e)?),
            "spectrum" => Color::Rgb(values::spectrum(e, in_emitter)?),
            "float" => Color::Rgb(Vec3::splat(values::float(e, e.need("value")?)?)),
            _ => Color::Texture(e),
        }))
    }

    /// Colour property `name` that may not be a texture (`default` when absent): a texture is
    /// refused with file:line, naming the property.
    pub fn rgb_only(&self, name: &str, default: Vec3) -> Result<Vec3, SceneError> {
        match self.color(name, false)? {
            None => Ok(default),
            Some(Color::Rgb(c)) => Ok(c),
            Some(Color::Texture(t)) => {
                Err(t.at.err(format!("{}: a texture for \"{name}\" is not supported yet", self.elem.what())))
            }
        }
    }

    /// Index-of-refraction property `name`: a `<float>` or a `<string>` naming a material of
    /// Mitsuba's table (`bk7`, `water`, ...), `default` (a table name) when absent.
    pub fn ior(&self, name: &str, default: &str) -> Result<f32, SceneError> {
        let Some(e) = self.get(name) else { return values::ior(self.elem, default) };
        self.expect(e, name, &["float", "string"])?;
        let v = values::ior(e, e.need("value")?)?;
        if !(v.is_finite() && v > 0.0) {
            return Err(e.at.err(format!("\"{name}\" must be a positive index of refraction, not {v}")));
        }
        Ok(v)
    }

    /// The nested objects of `tag` (named or not), marked read.
    pub fn objects(&self, tag: &str) -> Vec<&'e Elem> {
        self.items
            .iter()
            .filter(|i| i.e.tag == tag)
            .map(|i| {
                i.used.set(true);
                i.e
            })
            .collect()
    }

    /// The single nested object of `tag`, if any; two are an error.
    pub fn object(&self, tag: &str) -> Result<Option<&'e Elem>, SceneError> {
        let v = self.objects(tag);
        if v.len() > 1 {
            return Err(v[1].at.err(format!("{} takes one <{tag}>, not {}", self.elem.what(), v.len())));
        }
        Ok(v.first().copied())
    }

    /// Refuses property `name` when given: the renderer does not do it yet (`why`).
    pub fn refuse(&self, name: &str, why: &str) -> Result<(), SceneError> {
        match self.get(name) {
            Some(e) => Err(e.at.err(format!("{}: \"{name}\" is not supported ({why})", self.elem.what()))),
            None => Ok(()),
        }
    }

    /// Marks `name` read: a property that only tunes output or speed (listed in docs/formats.md).
    pub fn ignore(&self, name: &str) {
        let _ = self.find(name);
    }

    /// Warnings (`file:line: ...`) for the properties and objects the plugin did not read.
    pub fn unused(&self) -> Vec<String> {
        self.items
            .iter()
            .filter(|i| !i.used.get())
            .map(|i| match &i.name {
                Some(n) => format!("{}: {} does not use property \"{n}\"; ignored", i.e.at.show(), self.elem.what()),
                None => {
                    format!("{}: {} does not use the nested <{}>; ignored", i.e.at.show(), self.elem.what(), i.e.tag)
                }
            })
            .collect()
    }
}

#[cfg(test)]
mod tests {
    use super::super::doc::Loc;
    use super::*;
    use std::sync::Arc;

    fn el(tag: &str, attrs: &[(&str, &str)], line: usize) -> Elem {
        Elem {
            tag: tag.into(),
            attrs: attrs.iter().map(|(a, b)| (a.to_string(), b.to_string())).collect(),
            children: Vec::new(),
            at: Loc { file: Arc::new("s.xml".into()), line },
        }
    }

    #[test]
    fn unread_properties_are_reported_with_their_line() {
        let mut p = el("integrator", &[("type", "path")], 1);
        p.children = vec![
            el("integer", &[("name", "max_depth"), ("value", "3")], 2),
            el("float", &[("name", "bogus"), ("value", "1")], 3),
        ];
        let ids = HashMap::new();
        let props = Props::new(&p, &ids).unwrap();
        assert_eq!(props.int("max_depth", 5).unwrap(), 3);
        assert_eq!(props.int("rr_depth", 5).unwrap(), 5);
        let w = props.unused();
        assert_eq!(w.len(), 1);
        assert!(w[0].starts_with("s.xml:3:") && w[0].contains("\"bogus\""), "{w:?}");
        assert!(props.float("max_depth", 0.0).is_ok());
        assert!(props.bool("max_depth", false).unwrap_err().message.contains("must be <boolean>"));
    }

    #[test]
    fn refs_resolve_and_duplicates_are_refused() {
        let mut ids = HashMap::new();
        let mut b = el("bsdf", &[("type", "diffuse"), ("id", "white")], 4);
        b.children = vec![el("rgb", &[("name", "reflectance"), ("value", "0.5")], 5)];
        ids.insert("white".to_string(), b);
        let mut s = el("shape", &[("type", "sphere")], 9);
        s.children = vec![el("ref", &[("id", "white")], 10)];
        let props = Props::new(&s, &ids).unwrap();
        assert_eq!(props.objects("bsdf")[0].at.line, 4);
        s.children.push(el("ref", &[("id", "nope")], 11));
        assert!(Props::new(&s, &ids).err().unwrap().message.contains("no object has this id"));
        let mut d = el("shape", &[("type", "sphere")], 1);
        d.children = vec![
            el("float", &[("name", "radius"), ("value", "1")], 2),
            el("float", &[("name", "radius"), ("value", "2")], 3),
        ];
        assert!(Props::new(&d, &ids).err().unwrap().message.contains("given twice"));
    }
}
