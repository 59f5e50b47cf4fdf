//! `strata._strata`: the native half of the Python module. A thin layer over the library functions
//! the CLI runs (`strata::frontend`, `strata::session`, `strata::pointset`, `strata::report`): the
//! Python half (`strata/__init__.py`) turns keyword arguments into the CLI's flags and numpy arrays
//! into little-endian bytes, so nothing here decides anything the CLI does not.
//!
//! Renders run with the GIL released, on a scoped thread, while the calling thread polls Python's
//! signal handlers: Ctrl-C stops the render after its pass (as `strata render` does on SIGINT,
//! checkpoint included) and raises `KeyboardInterrupt`.

use pyo3::create_exception;
use pyo3::exceptions::{PyKeyboardInterrupt, PyRuntimeError};
use pyo3::prelude::*;
use pyo3::types::PyBytes;
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::Arc;
use strata::pointset::spec::Options;
use strata::pointset::{sampler_from_sets, PointSets};
use strata::session::{self, RenderOptions};

create_exception!(_strata, StrataError, PyRuntimeError, "An error strata reports (the CLI's message).");

fn err(e: impl ToString) -> PyErr {
    // The CLI's message without the line end a clap error carries.
    StrataError::new_err(e.to_string().trim_end().to_string())
}

/// f64 values from little-endian bytes.
fn f64s(bytes: &[u8]) -> Vec<f64> {
    bytes.chunks_exact(8).map(|c| f64::from_le_bytes(c.try_into().expect("8 bytes"))).collect()
}

/// f32 RGB triples from little-endian bytes.
fn rgb(bytes: &[u8]) -> Vec<[f32; 3]> {
    bytes
        .chunks_exact(12)
        .map(|c| std::array::from_fn(|i| f32::from_le_bytes(c[4 * i..4 * i + 4].try_into().expect("4 bytes"))))
        .collect()
}

fn rgb_bytes(v: &[[f32; 3]]) -> Vec<u8> {
    v.iter().flatten().flat_map(|x| x.to_le_bytes()).collect()
}

/// Checks an array of points (float64 bytes, shape `[sets, points, dims]`) as a file's points are
/// checked (messages name `<array NAME>`), and registers it as a sampler; returns the sampler's
/// name (`array:NAME:DIGEST?options`), which render flags then accept like a registry name.
fn array_sampler(
    name: &str,
    data: &[u8],
    shape: [usize; 3],
    options: &str,
) -> Result<strata::sampler::SamplerKind, String> {
    let source = format!("<array {name}>");
    let ps = PointSets::new(&source, shape[0], shape[1], shape[2], f64s(data)).map_err(|e| e.to_string())?;
    let mut opts = Options::default();
    options.split('&').filter(|kv| !kv.is_empty()).try_for_each(|kv| opts.set(kv)).map_err(|e| e.to_string())?;
    sampler_from_sets(&ps, &format!("array:{name}:{}", &ps.digest[..12.min(ps.digest.len())]), opts)
        .map_err(|e| e.to_string())
}

/// Checks and registers a point array ([`array_sampler`]); returns the sampler name to pass in
/// render flags (`--pixel-sampler NAME`).
#[pyfunction]
fn check_points(name: &str, data: &Bound<'_, PyBytes>, shape: [usize; 3], options: &str) -> PyResult<String> {
    array_sampler(name, data.as_bytes(), shape, options).map(|k| k.name().to_string()).map_err(err)
}

/// A render's result for Python: (mean RGB f32 bytes, variance-of-mean f32 bytes, width, height,
/// stats JSON).
type Rendered = (Py<PyBytes>, Py<PyBytes>, u32, u32, String);

/// A scene file parsed once (`strata.Scene`): renders given it start from the parsed scene.
#[pyclass(frozen, name = "ParsedScene")]
struct ParsedScene {
    desc: Arc<strata::scene::desc::SceneDesc>,
}

/// Parses the scene of `strata render ARGS` (its file, `--limit`s) once, with the CLI's checks.
#[pyfunction]
fn parse_scene(py: Python<'_>, args: Vec<String>) -> PyResult<ParsedScene> {
    let opts = strata::frontend::render_options(&args).map_err(err)?;
    let desc = py.detach(|| session::parse_scene(&opts)).map_err(err)?;
    Ok(ParsedScene { desc: Arc::new(desc) })
}

/// Renders `strata render ARGS` (point arrays are named in them after [`check_points`]; `scene`:
/// the file parsed already); `write`: also write the CLI's outputs (`-o`). Returns (mean RGB f32
/// bytes, variance-of-mean f32 bytes, width, height, stats JSON).
#[pyfunction]
#[pyo3(signature = (args, write, scene=None))]
fn render(py: Python<'_>, args: Vec<String>, write: bool, scene: Option<&ParsedScene>) -> PyResult<Rendered> {
    let mut opts: RenderOptions = strata::frontend::render_options(&args).map_err(err)?;
    opts.parsed = scene.map(|s| Arc::clone(&s.desc));
    let out = render_detached(py, opts, write)?;
    let (mean, var) = (out.film.mean(), out.film.variance_of_mean());
    let stats = session::stats_json(&out).to_string();
    let (w, h) = (out.film.width, out.film.height);
    Ok((PyBytes::new(py, &rgb_bytes(&mean)).unbind(), PyBytes::new(py, &rgb_bytes(&var)).unbind(), w, h, stats))
}

/// Runs `job` on a scoped thread with the GIL released, polling Python's signal handlers: a
/// signal sets `stop` (the render stops after its pass). Returns the job's result and the signal.
fn detached<T: Send>(py: Python<'_>, stop: &AtomicBool, job: impl FnOnce() -> T + Send) -> (T, Option<PyErr>) {
    py.detach(|| {
        std::thread::scope(|s| {
            let job = s.spawn(job);
            let mut signal = None;
            while !job.is_finished() {
                std::thread::sleep(std::time::Duration::from_millis(20));
                if signal.is_none() {
                    if let Err(e) = Python::attach(|py| py.check_signals()) {
                        stop.store(true, Ordering::SeqCst);
                        signal = Some(e);
                    }
                }
            }
            (job.join().unwrap_or_else(|p| std::panic::resume_unwind(p)), signal)
        })
    })
}

/// One render of `opts` (writing the CLI's outputs with `write`), Ctrl-C raising
/// `KeyboardInterrupt` after the pass (and the checkpoint the CLI would write).
fn render_detached(py: Python<'_>, mut opts: RenderOptions, write: bool) -> PyResult<session::RenderOutput> {
    let stop = Arc::new(AtomicBool::new(false));
    opts.stop = Some(Arc::clone(&stop));
    let outcome =
        detached(py, &stop, || if write { session::run_render(&opts) } else { session::render_to_film(&opts) });
    match outcome {
        (Ok(o), Some(e)) if e.is_instance_of::<PyKeyboardInterrupt>(py) => {
            let ck = o.checkpoint.as_ref().map_or(String::new(), |p| format!("; checkpoint {}", p.display()));
            Err(PyKeyboardInterrupt::new_err(format!("render interrupted after {} spp{ck}", o.film.samples().len())))
        }
        (_, Some(e)) => Err(e),
        (Err(e), None) => Err(err(e)),
        (Ok(o), None) => Ok(o),
    }
}

/// A reference for Python: a render's result and the EXR metadata the CLI writes, as (key, value)
/// pairs.
type Referenced = (Py<PyBytes>, Py<PyBytes>, u32, u32, String, Vec<(String, String)>);

/// Runs `strata reference ARGS` exactly as the CLI does ([`strata::frontend::reference_options`]:
/// `--first-sample jittered` unless given, the replicas and their variance layer); `write`: also
/// write its outputs (`-o`). Returns (mean RGB f32 bytes, variance f32 bytes (the replicas'
/// variance of the mean, or the i.i.d. one with one replica), width, height, stats JSON, EXR
/// metadata).
#[pyfunction]
#[pyo3(signature = (args, write, scene=None))]
fn reference(py: Python<'_>, args: Vec<String>, write: bool, scene: Option<&ParsedScene>) -> PyResult<Referenced> {
    let (mut opts, replicas) = strata::frontend::reference_options(&args).map_err(err)?;
    opts.parsed = scene.map(|s| Arc::clone(&s.desc));
    let bytes = |v: &[[f32; 3]]| PyBytes::new(py, &rgb_bytes(v)).unbind();
    if replicas < 2 {
        let out = render_detached(py, opts, write)?;
        let meta = session::output::metadata(&out);
        let (w, h) = (out.film.width, out.film.height);
        let stats = session::stats_json(&out).to_string();
        return Ok((bytes(&out.film.mean()), bytes(&out.film.variance_of_mean()), w, h, stats, meta));
    }
    let stop = Arc::new(AtomicBool::new(false));
    opts.stop = Some(Arc::clone(&stop));
    let run = || {
        if write {
            session::reference::run_reference(&opts, replicas)
        } else {
            session::reference::render_replicas(&opts, replicas)
        }
    };
    let rep = match detached(py, &stop, run) {
        (_, Some(e)) => return Err(e),
        (Err(e), None) => return Err(err(e)),
        (Ok(r), None) => r,
    };
    let meta = session::reference::replicated_metadata(&rep, opts.seed);
    let stats = session::reference::replicated_stats(&rep, opts.seed).to_string();
    let (w, h) = (rep.out.film.width, rep.out.film.height);
    Ok((bytes(&rep.mean), bytes(&rep.variance), w, h, stats, meta))
}

/// The options `strata CMD ARGS` resolves to (`render`, `reference` or `compare`), as debug text:
/// what the pytest suite compares between Python's calls and the CLI's flags, defaults included.
#[pyfunction]
fn resolve(cmd: &str, args: Vec<String>) -> PyResult<String> {
    match cmd {
        "render" => strata::frontend::render_options(&args).map(|o| format!("{o:?}")),
        "reference" => strata::frontend::reference_options(&args).map(|o| format!("{o:?}")),
        "compare" => strata::frontend::compare_args(&args).map(|o| format!("{o:?}")),
        _ => return Err(err(format!("resolve: unknown command {cmd}"))),
    }
    .map_err(err)
}

/// Runs `strata compare ARGS` (writing its outputs as the CLI does); returns the rows as JSON.
/// `call`: the Python call, which the report gives first under "Reproduce".
#[pyfunction]
#[pyo3(signature = (args, call=None))]
fn compare(py: Python<'_>, args: Vec<String>, call: Option<String>) -> PyResult<String> {
    let mut a = strata::frontend::compare_args(&args).map_err(err)?;
    // The report's commands: the Python call, then the CLI's equivalent of it (arrays appear by
    // their registered names), never `python script.py`.
    let quote = |s: &String| {
        if !s.is_empty() && s.chars().all(|c| c.is_ascii_alphanumeric() || "-_./=:,@%+".contains(c)) {
            s.clone()
        } else {
            format!("'{}'", s.replace('\'', "'\\''"))
        }
    };
    let cli = format!("strata compare {}", args.iter().map(quote).collect::<Vec<_>>().join(" "));
    a.commands = call.into_iter().chain([format!("{cli}  (the CLI's equivalent)")]).collect();
    // The message crosses the thread boundary (FrontendError is large; Python gets text anyway).
    let out = py.detach(|| strata::frontend::run_compare(&a).map_err(|e| e.to_string())).map_err(err)?;
    Ok(strata::report::to_json(&out.rows).to_string())
}

/// Mean squared error of two RGB f32 images (bytes of equal length), as `strata compare`.
#[pyfunction]
fn mse(a: &Bound<'_, PyBytes>, b: &Bound<'_, PyBytes>) -> PyResult<f64> {
    strata::report::mse(&rgb(a.as_bytes()), &rgb(b.as_bytes())).map_err(err)
}

/// Relative MSE of an RGB f32 image against a reference, as `strata compare`.
#[pyfunction]
fn relmse(a: &Bound<'_, PyBytes>, b: &Bound<'_, PyBytes>) -> PyResult<f64> {
    strata::report::rel_mse(&rgb(a.as_bytes()), &rgb(b.as_bytes())).map_err(err)
}

/// Mean FLIP (LDR, as `strata compare`'s FLIP column) of a linear RGB f32 image against a linear
/// reference (bytes of `width` x `height` pixels), and the per-pixel FLIP map as f32 bytes.
#[pyfunction]
fn flip(
    py: Python<'_>,
    a: &Bound<'_, PyBytes>,
    b: &Bound<'_, PyBytes>,
    width: u32,
    height: u32,
) -> PyResult<(f64, Py<PyBytes>)> {
    let (img, reference) = (rgb(a.as_bytes()), rgb(b.as_bytes()));
    let n = width as usize * height as usize;
    if img.len() != n || reference.len() != n {
        return Err(err(format!("flip: expected {width} x {height} pixels in both images")));
    }
    let map = strata::report::flip::flip_map(&reference, &img, width, height);
    let bytes: Vec<u8> = map.iter().flat_map(|v| v.to_le_bytes()).collect();
    Ok((strata::report::flip::mean(&map), PyBytes::new(py, &bytes).unbind()))
}

/// Reads an EXR as `strata render`/`reference` write it: (RGB f32 bytes, variance f32 bytes or
/// None, width, height, metadata as (key, value) pairs).
#[pyfunction]
#[allow(clippy::type_complexity)]
fn read_exr(
    py: Python<'_>,
    path: std::path::PathBuf,
) -> PyResult<(Py<PyBytes>, Option<Py<PyBytes>>, u32, u32, Vec<(String, String)>)> {
    let img = strata::film::read_exr(&path).map_err(|e| err(format!("{}: {e}", path.display())))?;
    let var = img.variance.as_ref().map(|v| PyBytes::new(py, &rgb_bytes(v)).unbind());
    Ok((PyBytes::new(py, &rgb_bytes(&img.rgb)).unbind(), var, img.width, img.height, img.meta))
}

/// The crate version.
#[pyfunction]
fn version() -> &'static str {
    env!("CARGO_PKG_VERSION")
}

/// The native module.
#[pymodule]
fn _strata(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add("StrataError", m.py().get_type::<StrataError>())?;
    m.add_class::<ParsedScene>()?;
    m.add_function(wrap_pyfunction!(parse_scene, m)?)?;
    m.add_function(wrap_pyfunction!(render, m)?)?;
    m.add_function(wrap_pyfunction!(compare, m)?)?;
    m.add_function(wrap_pyfunction!(reference, m)?)?;
    m.add_function(wrap_pyfunction!(resolve, m)?)?;
    m.add_function(wrap_pyfunction!(check_points, m)?)?;
    m.add_function(wrap_pyfunction!(mse, m)?)?;
    m.add_function(wrap_pyfunction!(relmse, m)?)?;
    m.add_function(wrap_pyfunction!(flip, m)?)?;
    m.add_function(wrap_pyfunction!(read_exr, m)?)?;
    m.add_function(wrap_pyfunction!(version, m)?)?;
    Ok(())
}
