//! What is wrong with one line of OBJ or MTL text: [`ObjLineError`], shared by the OBJ checks
//! ([`super::faces`]) and the MTL checks ([`super::mtl`]). The line number travels beside it
//! (`(line, message)` to the file's `SceneError`).

/// A line of OBJ or MTL text that strata cannot read (the texts quoted are already shortened).
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
pub enum ObjLineError {
    /// `v`, `vt` or `vn` with a count of numbers outside its range
    #[error("'{cmd}' expects {want} numbers ({what}), got {got}")]
    VertexNumbers {
        /// the keyword
        cmd: String,
        /// how many it takes ("3", "1 to 3")
        want: String,
        /// what they are ("x y z")
        what: &'static str,
        /// how many the line has
        got: usize,
    },
    /// an MTL statement with a count of numbers other than `n`
    #[error("'{cmd}' expects {n} number{}, got {got}", plural(*.n))]
    MtlNumbers {
        /// the keyword
        cmd: String,
        /// how many it takes
        n: usize,
        /// how many the line has
        got: usize,
    },
    /// a number that does not parse or is not finite
    #[error("'{cmd}' argument {arg}: expected a finite number, got '{text}'")]
    NotFinite {
        /// the keyword
        cmd: String,
        /// 1-based argument
        arg: usize,
        /// the argument as written
        text: String,
    },
    /// a negative (or non-finite) value where the MTL needs one >= 0
    #[error("'{cmd}' argument {arg}: expected a finite number >= 0, got '{text}'")]
    Negative {
        /// the keyword
        cmd: String,
        /// 1-based argument
        arg: usize,
        /// the argument as written
        text: String,
    },
    /// an MTL colour or value before the first `newmtl`
    #[error("'{cmd}' before any 'newmtl'")]
    BeforeNewmtl {
        /// the keyword
        cmd: String,
    },
    /// a `vn` of length 0
    #[error("'vn' {x} {y} {z} has zero length")]
    ZeroNormal {
        /// x as read
        x: f32,
        /// y as read
        y: f32,
        /// z as read
        z: f32,
    },
    /// a face with fewer than 3 vertices
    #[error("face 'f' needs at least 3 vertices, got {0}")]
    FewVertices(usize),
    /// a face vertex that is not `i`, `i/t`, `i//n` or `i/t/n`
    #[error("face vertex {vertex}: '{text}' is not i, i/t, i//n or i/t/n")]
    VertexForm {
        /// 1-based vertex of the face
        vertex: usize,
        /// the vertex as written
        text: String,
    },
    /// a face index that is not an integer
    #[error("face vertex {vertex}: '{text}' is not an index")]
    NotAnIndex {
        /// 1-based vertex of the face
        vertex: usize,
        /// the vertex as written
        text: String,
    },
    /// a face index (0, or beyond the list read so far)
    #[error("face vertex {vertex}: {what} index {index} out of range ({defined} defined so far)")]
    OutOfRange {
        /// 1-based vertex of the face
        vertex: usize,
        /// which list: "vertex", "texture coordinate", "normal"
        what: &'static str,
        /// the index as written
        index: i64,
        /// the length of that list so far
        defined: i64,
    },
}

fn plural(n: usize) -> &'static str {
    if n == 1 {
        ""
    } else {
        "s"
    }
}
