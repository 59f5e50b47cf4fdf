//! What the compile-time registries share (`sampler::SAMPLERS`, `light::select::RULES`): a
//! registered name found in a `const fn`, where `str`'s `==` cannot run.

/// Whether `a` and `b` are the same string, usable in consts (`SamplerKind::named`,
/// `LightSelection::named`).
pub const fn same_name(a: &str, b: &str) -> bool {
    let (a, b) = (a.as_bytes(), b.as_bytes());
    if a.len() != b.len() {
        return false;
    }
    let mut i = 0;
    while i < a.len() {
        if a[i] != b[i] {
            return false;
        }
        i += 1;
    }
    true
}

#[cfg(test)]
mod tests {
    use super::same_name;

    #[test]
    fn names_are_equal_only_when_every_byte_is() {
        const YES: bool = same_name("power", "power");
        assert!(YES && same_name("", ""));
        assert!(!same_name("power", "powe") && !same_name("power", "Power") && !same_name("a", ""));
    }
}
