//! Long work off the page's thread: a Web Worker (`fairmesh_worker.js`) runs this same module as
//! an engine that keeps the document's mesh, the hierarchy it built and the fairing workspace,
//! so that the page answers while the hierarchy is built or a level is faired. A second worker,
//! the measuring worker, measures each faired result (the numbers and the heat map), so that a
//! fairing never waits behind a measuring.
//!
//! - The page side ([`post_hierarchy`], [`post_fair`], [`post_prepare`], [`post_noise`],
//!   [`post_measure`], [`tick`]) sends one request at a time to each worker, as a message of
//!   typed arrays (positions, triangles, a mask) and the settings as JSON; the others wait in
//!   order (a fairing replaces the fairing still waiting, as on the desktop's compute thread, and
//!   setting up the levels waits for everything else). Answers come back with their arrays
//!   transferred, not copied, and become the same [`JobResult`]s the desktop's threads send, with
//!   the same progress.
//! - The measuring worker keeps the meshes it measures against (the document's and the clean
//!   one): a request sends the result only. A newer measuring, or the view moving on, ends it, as
//!   the desktop's measuring stops half way; a fresh one starts with the next request, which
//!   carries the meshes again.
//! - The engine keeps what it built: a slider step sends the level and the settings only. When
//!   it does not hold the hierarchy a request is for (it was started afresh, or an undo brought
//!   back an older one), the request carries the mesh and the hierarchy as bytes
//!   ([`fairmesh::hierarchy::Hierarchy::to_bytes`]) and the engine takes them.
//! - Cancel: a worker cannot read a message while the module runs, so a request that is no
//!   longer wanted (Cancel, another file, other hierarchy settings) ends the worker; a fresh one
//!   starts with the next request, which carries what the engine needs again.
//! - Where no worker can be started (or the settings do not come back from JSON exactly, or the
//!   page was opened with `?worker=0`), the post functions give the job back and the caller runs
//!   it on the page, between frames.

use std::cell::RefCell;
use std::collections::VecDeque;
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::mpsc::Sender;
use std::sync::{Arc, Mutex, PoisonError};
use std::time::Duration;

use fairmesh::fairing::{FairPhases, FairReport, Mask, Method};
use fairmesh::hierarchy::{Hierarchy, HierarchyError};
use fairmesh::multires::MultiresWorkspace;
use fairmesh::{Topology, TriMesh};
use wasm_bindgen::closure::Closure;
use wasm_bindgen::prelude::*;
use wasm_bindgen::JsCast;

use crate::app::compute::denoise_and_build;
use crate::app::compute::FairJob;
use crate::app::generation::{Generation, GenerationId};
use crate::app::jobs::{Faired, JobKind, JobResult, JobTicket, SharedProgress};
use crate::app::sharp_edges::SharpEdgeLines;
use crate::app::state::{DenoiseSummary, KeptHierarchy, Measures, Settings};

/// The engine's script, beside the page (`web/fairmesh_worker.js`).
const WORKER_SCRIPT: &str = "./fairmesh_worker.js";

mod js {
    use wasm_bindgen::prelude::*;

    #[wasm_bindgen]
    extern "C" {
        /// The browser's `Worker`.
        pub type Worker;
        #[wasm_bindgen(constructor, catch)]
        pub fn new(url: &str, options: &JsValue) -> Result<Worker, JsValue>;
        #[wasm_bindgen(method, catch, js_name = postMessage)]
        pub fn post(this: &Worker, message: &JsValue, transfer: &JsValue) -> Result<(), JsValue>;
        #[wasm_bindgen(method)]
        pub fn terminate(this: &Worker);
        #[wasm_bindgen(method, setter = onmessage)]
        pub fn set_onmessage(this: &Worker, handler: &js_sys::Function);
        #[wasm_bindgen(method, setter = onerror)]
        pub fn set_onerror(this: &Worker, handler: &js_sys::Function);

        /// The worker's own `postMessage` (to the page), called in the engine.
        #[wasm_bindgen(js_name = postMessage)]
        pub fn post_to_page(message: &JsValue, transfer: &JsValue);
    }
}

fn get(object: &JsValue, name: &str) -> JsValue {
    js_sys::Reflect::get(object, &name.into()).unwrap_or(JsValue::UNDEFINED)
}

fn set(object: &js_sys::Object, name: &str, value: impl Into<JsValue>) {
    // Setting a property on a plain object cannot fail.
    let _ = js_sys::Reflect::set(object, &name.into(), &value.into());
}

fn number(object: &JsValue, name: &str) -> f64 {
    get(object, name).as_f64().unwrap_or(f64::NAN)
}

fn text(object: &JsValue, name: &str) -> Option<String> {
    get(object, name).as_string()
}

fn flat_positions(positions: &[[f32; 3]]) -> js_sys::Float32Array {
    let flat: Vec<f32> = positions.iter().flatten().copied().collect();
    js_sys::Float32Array::from(flat.as_slice())
}

fn flat_triangles(triangles: &[[u32; 3]]) -> js_sys::Uint32Array {
    let flat: Vec<u32> = triangles.iter().flatten().copied().collect();
    js_sys::Uint32Array::from(flat.as_slice())
}

fn positions_from(value: &JsValue) -> Vec<[f32; 3]> {
    let flat = value
        .dyn_ref::<js_sys::Float32Array>()
        .map(js_sys::Float32Array::to_vec)
        .unwrap_or_default();
    flat.chunks_exact(3).map(|p| [p[0], p[1], p[2]]).collect()
}

fn words_from(value: &JsValue) -> Vec<u32> {
    value
        .dyn_ref::<js_sys::Uint32Array>()
        .map(js_sys::Uint32Array::to_vec)
        .unwrap_or_default()
}

/// The mesh of a request's `{prefix}positions` and `{prefix}triangles`, if it has them.
fn mesh_from(message: &JsValue, prefix: &str) -> Option<TriMesh> {
    let positions = get(message, &format!("{prefix}positions"));
    if positions.is_undefined() {
        return None;
    }
    let triangles = words_from(&get(message, &format!("{prefix}triangles")))
        .chunks_exact(3)
        .map(|t| [t[0], t[1], t[2]])
        .collect();
    Some(TriMesh::new(positions_from(&positions), triangles))
}

/// Sets `{prefix}positions` and `{prefix}triangles` on `message` to `mesh`'s, transferred.
fn set_mesh(message: &js_sys::Object, transfer: &js_sys::Array, prefix: &str, mesh: &TriMesh) {
    let positions = flat_positions(&mesh.positions);
    let triangles = flat_triangles(&mesh.triangles);
    transfer.push(&positions.buffer());
    transfer.push(&triangles.buffer());
    set(message, &format!("{prefix}positions"), positions);
    set(message, &format!("{prefix}triangles"), triangles);
}

/// A result's measures as a message's object (the heat map's distances transferred).
fn measures_to_js(measures: &Measures, transfer: &js_sys::Array) -> js_sys::Object {
    let object = js_sys::Object::new();
    let optional = |value: Option<f64>| value.map_or(JsValue::UNDEFINED, JsValue::from);
    set(
        &object,
        "volume_change_percent",
        optional(measures.volume_change_percent),
    );
    set(&object, "mean_distance", measures.mean_distance);
    set(&object, "max_distance", measures.max_distance);
    set(&object, "vertex_rms", optional(measures.vertex_rms));
    set(
        &object,
        "barycenter_drift",
        optional(measures.barycenter_drift),
    );
    let distances = js_sys::Float32Array::from(measures.vertex_distances.as_slice());
    transfer.push(&distances.buffer());
    set(&object, "vertex_distances", distances);
    object
}

/// The measures [`measures_to_js`] sent, if `value` holds them for `vertices` vertices.
fn measures_from_js(value: &JsValue, vertices: usize) -> Option<Measures> {
    let distances = get(value, "vertex_distances")
        .dyn_ref::<js_sys::Float32Array>()?
        .to_vec();
    if distances.len() != vertices {
        return None;
    }
    Some(Measures {
        volume_change_percent: get(value, "volume_change_percent").as_f64(),
        mean_distance: get(value, "mean_distance").as_f64()?,
        max_distance: get(value, "max_distance").as_f64()?,
        vertex_rms: get(value, "vertex_rms").as_f64(),
        barycenter_drift: get(value, "barycenter_drift").as_f64(),
        vertex_distances: Arc::new(distances),
    })
}

fn describe(error: &JsValue) -> String {
    error
        .as_string()
        .or_else(|| text(error, "message"))
        .unwrap_or_else(|| format!("{error:?}"))
}

// ---------------------------------------------------------------------------------------------
// The engine (runs in the worker).

/// What the engine keeps between requests.
struct Held {
    hierarchy: Arc<Hierarchy>,
    original: Arc<TriMesh>,
    topology: Arc<Topology>,
    /// The hierarchy was built on the denoised mesh.
    denoised: bool,
    workspace: Arc<Mutex<MultiresWorkspace>>,
}

/// What the measuring worker measures each result against: the document's mesh and the clean
/// mesh (the one before the noise), if there is one.
struct Against {
    base: TriMesh,
    clean: Option<TriMesh>,
}

thread_local! {
    static HELD: RefCell<Option<Held>> = const { RefCell::new(None) };
    static AGAINST: RefCell<Option<Arc<Against>>> = const { RefCell::new(None) };
}

/// Posts `fields` to the page as `{kind, ...fields}`, transferring `transfer`'s buffers.
fn answer(kind: &str, fill: impl FnOnce(&js_sys::Object), transfer: &js_sys::Array) {
    let message = js_sys::Object::new();
    set(&message, "kind", kind);
    fill(&message);
    js::post_to_page(&message, transfer);
}

/// A progress hook that tells the page every percent (and when the denoise is done).
fn progress_to_page() -> impl FnMut(f32) -> bool + Send {
    let mut last = -1.0_f32;
    move |fraction: f32| {
        if (fraction - last).abs() >= 0.01 || fraction >= 1.0 {
            last = fraction;
            answer(
                "progress",
                |m| set(m, "fraction", f64::from(fraction)),
                &js_sys::Array::new(),
            );
        }
        true
    }
}

fn settings_from(message: &JsValue) -> Result<Settings, String> {
    let json = text(message, "settings").ok_or("the request has no settings")?;
    serde_json::from_str(&json).map_err(|error| format!("the request's settings: {error}"))
}

/// Takes the state a request carries (the mesh and the hierarchy as bytes), if it carries one.
fn take_state(message: &JsValue) -> Result<(), String> {
    let bytes = get(message, "hierarchy");
    let Some(bytes) = bytes.dyn_ref::<js_sys::Uint8Array>() else {
        return Ok(());
    };
    let hierarchy = Hierarchy::from_bytes(&bytes.to_vec()).map_err(|e| e.to_string())?;
    let original = mesh_from(message, "").ok_or("the request has no mesh")?;
    let topology = Topology::build(&original);
    HELD.with(|held| {
        *held.borrow_mut() = Some(Held {
            hierarchy: Arc::new(hierarchy),
            original: Arc::new(original),
            topology: Arc::new(topology),
            denoised: get(message, "denoised").is_truthy(),
            workspace: Arc::default(),
        });
    });
    Ok(())
}

/// The engine's answer to one request from the page (`fairmesh_worker.js` calls it for each
/// message). A request it cannot read is answered with `failed`.
pub fn handle(message: JsValue) {
    let kind = text(&message, "kind").unwrap_or_default();
    let outcome = match kind.as_str() {
        "hierarchy" => build_hierarchy(&message),
        "fair" => take_state(&message).and_then(|()| fair(&message)),
        "prepare" => take_state(&message).and_then(|()| prepare(&message)),
        "noise" => noise(&message),
        "measure" => measure(&message),
        _ => Err(format!("unknown request {kind:?}")),
    };
    if let Err(error) = outcome {
        answer(
            "failed",
            |m| set(m, "message", error.as_str()),
            &js_sys::Array::new(),
        );
    }
}

fn build_hierarchy(message: &JsValue) -> Result<(), String> {
    let settings = settings_from(message)?;
    let mesh = Arc::new(mesh_from(message, "").ok_or("the request has no mesh")?);
    let file_edges: Vec<[u32; 2]> = words_from(&get(message, "file_edges"))
        .chunks_exact(2)
        .map(|e| [e[0], e[1]])
        .collect();
    let topology = Arc::new(Topology::build(&mesh));
    // Whatever the engine held is for another hierarchy now.
    HELD.with(|held| held.borrow_mut().take());
    let mut progress = progress_to_page();
    let mut denoised = |_: Option<&TriMesh>| {
        answer(
            "progress",
            |m| {
                set(m, "fraction", 0.0);
                set(m, "denoised", true);
            },
            &js_sys::Array::new(),
        );
    };
    let result = denoise_and_build(
        &mesh,
        &topology,
        settings.hierarchy.options(),
        settings.denoise_options(),
        &|_: &TriMesh| file_edges.clone(),
        &mut progress,
        &mut denoised,
    );
    match result {
        Ok(kept) => {
            let bytes = js_sys::Uint8Array::from(kept.hierarchy.to_bytes().as_slice());
            let transfer = js_sys::Array::of1(&bytes.buffer());
            let denoise = kept.denoise.as_ref().map(|d| {
                serde_json::json!({
                    "time_ms": d.time.as_secs_f64() * 1e3,
                    "report": report_json(&d.report),
                })
                .to_string()
            });
            HELD.with(|held| {
                *held.borrow_mut() = Some(Held {
                    hierarchy: kept.hierarchy.clone(),
                    original: mesh.clone(),
                    topology: topology.clone(),
                    denoised: kept.denoise.is_some(),
                    workspace: Arc::default(),
                });
            });
            answer(
                "hierarchy",
                |m| {
                    set(m, "bytes", bytes);
                    set(m, "build_ms", kept.build_time.as_secs_f64() * 1e3);
                    set(m, "matches", kept.base_matches_original);
                    if let Some(denoise) = denoise {
                        set(m, "denoise", denoise);
                    }
                },
                &transfer,
            );
        }
        Err(error) => answer(
            "hierarchy",
            |m| set(m, "error", error.to_string()),
            &js_sys::Array::new(),
        ),
    }
    Ok(())
}

/// The parts of the held state a request needs, or why there is none.
fn held<T>(with: impl FnOnce(&Held) -> T) -> Result<T, String> {
    HELD.with(|held| {
        held.borrow()
            .as_ref()
            .map(with)
            .ok_or_else(|| "the engine holds no hierarchy".to_owned())
    })
}

fn fair(message: &JsValue) -> Result<(), String> {
    let settings = settings_from(message)?;
    let level = number(message, "level");
    if level.is_nan() || level < 0.0 {
        return Err("the request has no level".into());
    }
    let mask = match get(message, "mask").dyn_ref::<js_sys::Float32Array>() {
        Some(weights) => Some(Mask::new(weights.to_vec()).map_err(|e| e.to_string())?),
        None => None,
    };
    let (job, workspace) = held(|held| {
        (
            FairJob::new(
                held.hierarchy.clone(),
                held.original.clone(),
                held.denoised,
                mask,
                held.topology.clone(),
                &settings,
                level as usize,
            ),
            held.workspace.clone(),
        )
    })?;
    match job.run(&workspace, progress_to_page()) {
        Some(faired) => {
            let positions = flat_positions(&faired.positions);
            let transfer = js_sys::Array::of1(&positions.buffer());
            answer(
                "faired",
                |m| {
                    set(m, "positions", positions);
                    set(m, "volume_change", faired.volume_change);
                    set(m, "rms_displacement", faired.rms_displacement);
                    set(m, "folds_left", faired.folds_left as f64);
                    set(m, "elapsed_ms", faired.elapsed.as_secs_f64() * 1e3);
                },
                &transfer,
            );
        }
        None => answer("faired", |_| {}, &js_sys::Array::new()),
    }
    Ok(())
}

/// Sets up every level of the held hierarchy for fairing (the desktop's idle level set-up).
fn prepare(message: &JsValue) -> Result<(), String> {
    let settings = settings_from(message)?;
    let (hierarchy, workspace) = held(|held| (held.hierarchy.clone(), held.workspace.clone()))?;
    let mut workspace = workspace.lock().unwrap_or_else(PoisonError::into_inner);
    for level in 1..hierarchy.level_count() {
        workspace.prepare_for(&hierarchy, &settings.fairing.multires_options(level));
    }
    answer("prepared", |_| {}, &js_sys::Array::new());
    Ok(())
}

/// Adds noise to a copy of the request's mesh and measures it against the clean mesh (the
/// request's `clean_` mesh, else its mesh), as the desktop's io thread does.
fn noise(message: &JsValue) -> Result<(), String> {
    let settings = settings_from(message)?;
    let mesh = mesh_from(message, "").ok_or("the request has no mesh")?;
    let clean = mesh_from(message, "clean_");
    let mut noisy = mesh.clone();
    fairmesh::noise::add_noise(&mut noisy, &settings.noise.options());
    let against_clean = Measures::of(clean.as_ref().unwrap_or(&mesh), &noisy);
    let transfer = js_sys::Array::new();
    let positions = flat_positions(&noisy.positions);
    transfer.push(&positions.buffer());
    let measures = measures_to_js(&against_clean, &transfer);
    answer(
        "noised",
        |m| {
            set(m, "positions", positions);
            set(m, "against_clean", measures);
        },
        &transfer,
    );
    Ok(())
}

/// Measures a faired result (the request's `positions` on the document mesh's triangles) against
/// the document's mesh and the clean one (if any), as the desktop's measuring thread does. A
/// request that carries `meshes` brings those two (`base_` and `clean_`), and the measuring
/// worker keeps them for the requests after it.
fn measure(message: &JsValue) -> Result<(), String> {
    let started = web_time::Instant::now();
    if get(message, "meshes").is_truthy() {
        let base = mesh_from(message, "base_").ok_or("the request has no mesh")?;
        let clean = mesh_from(message, "clean_");
        AGAINST.with(|held| *held.borrow_mut() = Some(Arc::new(Against { base, clean })));
    }
    let against = AGAINST
        .with(|held| held.borrow().clone())
        .ok_or("the measuring worker holds no mesh")?;
    let base = &against.base;
    let faired = TriMesh {
        positions: positions_from(&get(message, "positions")),
        triangles: base.triangles.clone(),
    };
    if faired.positions.len() != base.positions.len() {
        return Err("the result to measure does not fit the mesh".into());
    }
    let against_document = Measures::of(base, &faired);
    let against_clean = against
        .clean
        .as_ref()
        .map(|clean| Measures::of(clean, &faired));
    let transfer = js_sys::Array::new();
    let against_document = measures_to_js(&against_document, &transfer);
    let against_clean = against_clean.map(|m| measures_to_js(&m, &transfer));
    let elapsed = started.elapsed();
    answer(
        "measured",
        |m| {
            set(m, "against_document", against_document);
            if let Some(against_clean) = against_clean {
                set(m, "against_clean", against_clean);
            }
            set(m, "measure_ms", elapsed.as_secs_f64() * 1e3);
        },
        &transfer,
    );
    Ok(())
}

/// The fairing report's fields as JSON (the page shows them).
fn report_json(report: &FairReport) -> serde_json::Value {
    serde_json::json!({
        "iterations_run": report.iterations_run,
        "rounds_run": report.rounds_run,
        "max_move": report.max_move,
        "noise_estimate": report.noise_estimate,
        "tangential_noise": report.tangential_noise,
        "crease_edges": report.crease_edges,
        "loose_triangles": report.loose_triangles,
        "detection_ms": report.detection_ms,
        "phases": [report.phases.set_up, report.phases.iterations, report.phases.volume,
                   report.phases.relaxation, report.phases.risk],
        "risk_by_round": report.risk_by_round,
    })
}

fn report_from_json(json: &serde_json::Value) -> FairReport {
    let count = |name: &str| json[name].as_u64().unwrap_or(0) as usize;
    let real = |name: &str| json[name].as_f64().unwrap_or(0.0);
    let phase = |i: usize| json["phases"][i].as_f64().unwrap_or(0.0);
    FairReport {
        iterations_run: count("iterations_run"),
        rounds_run: count("rounds_run"),
        max_move: real("max_move"),
        noise_estimate: json["noise_estimate"].as_f64(),
        tangential_noise: json["tangential_noise"].as_f64(),
        crease_edges: count("crease_edges"),
        loose_triangles: count("loose_triangles"),
        detection_ms: real("detection_ms"),
        phases: FairPhases {
            set_up: phase(0),
            iterations: phase(1),
            volume: phase(2),
            relaxation: phase(3),
            risk: phase(4),
        },
        risk_by_round: json["risk_by_round"]
            .as_array()
            .map(|values| {
                values
                    .iter()
                    .filter_map(serde_json::Value::as_f64)
                    .collect()
            })
            .unwrap_or_default(),
    }
}

// ---------------------------------------------------------------------------------------------
// The page's side.

/// Where a result goes back to the app, as the desktop's jobs send it.
pub(in crate::app) struct Sending {
    pub(in crate::app) tx: Sender<(JobResult, JobTicket)>,
    pub(in crate::app) ctx: egui::Context,
    pub(in crate::app) ticket: JobTicket,
}

/// The hierarchy a request works on, sent along unless the engine holds it already.
struct State {
    hierarchy: Arc<Hierarchy>,
    original: Arc<TriMesh>,
    denoised: bool,
}

enum Reply {
    Hierarchy {
        document: GenerationId,
        generation: GenerationId,
        hierarchy_generation: Generation,
        mesh: Arc<TriMesh>,
        denoising: Arc<AtomicBool>,
    },
    Fair {
        document: GenerationId,
        view: GenerationId,
        level: usize,
        method: Method,
    },
    Prepare,
    Noise {
        document: GenerationId,
        label: String,
        /// The document's mesh: the noisy one has its triangles.
        mesh: Arc<TriMesh>,
        clean: Arc<TriMesh>,
    },
    Measure {
        document: GenerationId,
        serial: u64,
        /// The result being measured (given back when the measuring stops).
        positions: Arc<Vec<[f32; 3]>>,
        view_generation: Generation,
        /// The view the result was measured for: the measuring stops when it moves on.
        view: GenerationId,
    },
}

/// The meshes a measuring is against (the document's and the clean one), sent along unless the
/// measuring worker holds them already.
#[derive(Clone)]
struct AgainstMeshes {
    base: Arc<TriMesh>,
    clean: Option<Arc<TriMesh>>,
}

impl AgainstMeshes {
    fn same(&self, other: &Self) -> bool {
        Arc::ptr_eq(&self.base, &other.base)
            && match (&self.clean, &other.clean) {
                (Some(a), Some(b)) => Arc::ptr_eq(a, b),
                (None, None) => true,
                _ => false,
            }
    }
}

struct Request {
    message: js_sys::Object,
    transfer: js_sys::Array,
    state: Option<State>,
    against: Option<AgainstMeshes>,
    reply: Reply,
    /// The document the request is for.
    document: GenerationId,
    document_generation: Generation,
    progress: SharedProgress,
    sending: Sending,
}

impl Request {
    fn kind(&self) -> JobKind {
        match self.reply {
            Reply::Hierarchy { .. } => JobKind::Hierarchy,
            Reply::Fair { .. } => JobKind::Fair,
            Reply::Prepare => JobKind::LevelSetUp,
            Reply::Noise { .. } => JobKind::Noise,
            Reply::Measure { .. } => JobKind::Measure,
        }
    }

    /// Nobody wants the answer any more.
    fn is_stale(&self) -> bool {
        if !self.document_generation.is_current(self.document) {
            return true;
        }
        match &self.reply {
            Reply::Hierarchy {
                generation,
                hierarchy_generation,
                ..
            } => !hierarchy_generation.is_current(*generation),
            _ => false,
        }
    }

    /// A measuring whose result the view no longer shows, or soon will not (the slider moved,
    /// an option changed): it stops, as on the desktop, to leave the cores to the next fairing.
    fn moved_on(&self) -> bool {
        match &self.reply {
            Reply::Measure {
                view_generation,
                view,
                ..
            } => !view_generation.is_current(*view),
            _ => false,
        }
    }
}

/// The page's two workers: the engine (the hierarchy, fairing, noise) and the measuring worker,
/// so that a fairing never waits for a measuring.
#[derive(Clone, Copy, PartialEq, Eq)]
enum Role {
    Engine,
    Measurer,
}

impl Role {
    fn with<T>(self, f: impl FnOnce(&mut Engine) -> T) -> T {
        let cell = match self {
            Role::Engine => &ENGINE,
            Role::Measurer => &MEASURER,
        };
        cell.with(|engine| f(&mut engine.borrow_mut()))
    }
}

/// A handler of the worker's events.
type Handler = Closure<dyn FnMut(JsValue)>;

/// A worker and its requests.
struct Engine {
    role: Role,
    /// The worker, with its message and error handlers.
    worker: Option<(js::Worker, Handler, Handler)>,
    /// No worker could be started: jobs run on the page.
    unavailable: bool,
    in_flight: Option<Request>,
    waiting: VecDeque<Request>,
    /// Runs when nothing else waits.
    idle: VecDeque<Request>,
    /// The hierarchy the engine holds (the page's copy of it).
    held: Option<Arc<Hierarchy>>,
    /// The meshes the measuring worker holds.
    held_against: Option<AgainstMeshes>,
    /// Messages the worker sent (progress and answers), counted since the page started.
    heard: u64,
    /// The handlers of ended workers.
    retired: Vec<(Handler, Handler)>,
}

thread_local! {
    static ENGINE: RefCell<Engine> = RefCell::new(Engine::new(Role::Engine));
    static MEASURER: RefCell<Engine> = RefCell::new(Engine::new(Role::Measurer));
}

/// A job's message to the worker: its kind and the settings as JSON; `None` when the settings
/// do not come back from JSON exactly (the job then runs on the page).
fn job_message(kind: &str, settings: &Settings) -> Option<js_sys::Object> {
    let settings = settings_json(settings)?;
    let message = js_sys::Object::new();
    set(&message, "kind", kind);
    set(&message, "settings", settings);
    Some(message)
}

/// The settings as JSON, if they come back from it exactly (else the job runs on the page).
fn settings_json(settings: &Settings) -> Option<String> {
    let json = serde_json::to_string(settings).ok()?;
    let back: Settings = serde_json::from_str(&json).ok()?;
    (back == *settings).then_some(json)
}

impl Engine {
    fn new(role: Role) -> Self {
        Self {
            role,
            worker: None,
            unavailable: false,
            in_flight: None,
            waiting: VecDeque::new(),
            idle: VecDeque::new(),
            held: None,
            held_against: None,
            heard: 0,
            retired: Vec::new(),
        }
    }

    fn ensure_worker(&mut self) -> bool {
        if self.worker.is_some() {
            return true;
        }
        if self.unavailable {
            return false;
        }
        // `?worker=0`: the long jobs run on the page's thread (to compare, or where a worker
        // misbehaves).
        let search = web_sys::window().and_then(|w| w.location().search().ok());
        if search.is_some_and(|search| {
            web_sys::UrlSearchParams::new_with_str(&search)
                .ok()
                .and_then(|params| params.get("worker"))
                .as_deref()
                == Some("0")
        }) {
            self.unavailable = true;
            return false;
        }
        let options = js_sys::Object::new();
        set(&options, "type", "module");
        let worker = match js::Worker::new(WORKER_SCRIPT, &options) {
            Ok(worker) => worker,
            Err(error) => {
                let warning = format!(
                    "fairmesh: no worker for long jobs ({}); they run on the page",
                    describe(&error)
                );
                web_sys::console::warn_1(&warning.into());
                self.unavailable = true;
                return false;
            }
        };
        let role = self.role;
        let on_message = Handler::new(move |event: JsValue| {
            let data = get(&event, "data");
            role.with(|engine| engine.on_message(&data));
        });
        let on_error = Handler::new(move |event: JsValue| {
            let message = text(&event, "message").unwrap_or_else(|| "the worker failed".into());
            let data = js_sys::Object::new();
            set(&data, "kind", "failed");
            set(&data, "message", message);
            role.with(|engine| engine.on_message(&data));
        });
        worker.set_onmessage(on_message.as_ref().unchecked_ref());
        worker.set_onerror(on_error.as_ref().unchecked_ref());
        // The page compiled the module once (index.html); the worker instantiates the same one.
        let init = js_sys::Object::new();
        set(&init, "kind", "init");
        if let Some(window) = web_sys::window() {
            set(&init, "module", get(&window, "fairmeshModule"));
        }
        if worker.post(&init, &js_sys::Array::new()).is_err() {
            self.unavailable = true;
            return false;
        }
        self.worker = Some((worker, on_message, on_error));
        true
    }

    /// Ends the worker (and whatever it was doing); the next request starts a fresh one.
    fn end_worker(&mut self) {
        if let Some((worker, on_message, on_error)) = self.worker.take() {
            worker.terminate();
            // This may run inside one of the worker's handlers: they are dropped next frame.
            self.retired.push((on_message, on_error));
        }
        self.held = None;
        self.held_against = None;
        self.in_flight = None;
    }

    fn queue(&mut self, request: Request, idle: bool) -> bool {
        if !self.ensure_worker() {
            return false;
        }
        if idle {
            self.idle.push_back(request);
        } else {
            if matches!(request.reply, Reply::Fair { .. }) {
                // A newer fairing replaces the one still waiting (its ticket ends with it).
                self.waiting
                    .retain(|r| !matches!(r.reply, Reply::Fair { .. }));
            }
            if matches!(request.reply, Reply::Measure { .. }) {
                // So does a newer measuring, and it ends the one in flight: that one's result
                // is no longer on screen. The measuring worker starts again with the meshes.
                self.waiting
                    .retain(|r| !matches!(r.reply, Reply::Measure { .. }));
                if self
                    .in_flight
                    .as_ref()
                    .is_some_and(|r| matches!(r.reply, Reply::Measure { .. }))
                {
                    self.end_worker();
                }
            }
            self.waiting.push_back(request);
        }
        self.send_next();
        true
    }

    fn send_next(&mut self) {
        if self.in_flight.is_some() {
            return;
        }
        self.waiting.retain(|r| !r.is_stale());
        self.idle.retain(|r| !r.is_stale());
        let Some(request) = self.waiting.pop_front().or_else(|| self.idle.pop_front()) else {
            return;
        };
        if !self.ensure_worker() {
            // The worker could not be started again: the request is lost, and says so.
            let kind = request.kind();
            fail(
                request,
                kind,
                "no worker could be started for the job".into(),
            );
            return;
        }
        if let Some(state) = &request.state {
            let holds = self
                .held
                .as_ref()
                .is_some_and(|held| Arc::ptr_eq(held, &state.hierarchy));
            if !holds {
                let bytes = js_sys::Uint8Array::from(state.hierarchy.to_bytes().as_slice());
                request.transfer.push(&bytes.buffer());
                set(&request.message, "hierarchy", bytes);
                set_mesh(&request.message, &request.transfer, "", &state.original);
                set(&request.message, "denoised", state.denoised);
                self.held = Some(state.hierarchy.clone());
            }
        }
        if let Some(against) = &request.against {
            let holds = self
                .held_against
                .as_ref()
                .is_some_and(|held| held.same(against));
            if !holds {
                set(&request.message, "meshes", true);
                set_mesh(&request.message, &request.transfer, "base_", &against.base);
                if let Some(clean) = &against.clean {
                    set_mesh(&request.message, &request.transfer, "clean_", clean);
                }
                self.held_against = Some(against.clone());
            }
        }
        let sent = self
            .worker
            .as_ref()
            .map(|(worker, _, _)| worker.post(&request.message, &request.transfer));
        match sent {
            Some(Ok(())) => self.in_flight = Some(request),
            Some(Err(error)) => {
                let kind = request.kind();
                fail(
                    request,
                    kind,
                    format!("could not post the job ({})", describe(&error)),
                );
                self.end_worker();
            }
            None => {}
        }
    }

    fn on_message(&mut self, data: &JsValue) {
        self.heard += 1;
        let kind = text(data, "kind").unwrap_or_default();
        if kind == "progress" {
            if let Some(request) = &self.in_flight {
                request.progress.set(number(data, "fraction") as f32);
                if let Reply::Hierarchy { denoising, .. } = &request.reply {
                    if get(data, "denoised").is_truthy() {
                        denoising.store(false, Ordering::Relaxed);
                    }
                }
                request.sending.ctx.request_repaint();
            }
            return;
        }
        let Some(request) = self.in_flight.take() else {
            return;
        };
        match kind.as_str() {
            "failed" => {
                let message = text(data, "message").unwrap_or_default();
                let job = request.kind();
                fail(request, job, message);
                // A module that trapped cannot be trusted with another job.
                self.end_worker();
            }
            "hierarchy" => {
                if let Some(hierarchy) = on_hierarchy(request, data) {
                    self.held = Some(hierarchy);
                }
            }
            "faired" => on_faired(request, data),
            "noised" => on_noised(request, data),
            "measured" => on_measured(request, data),
            _ => drop(request),
        }
        self.send_next();
    }

    /// Ends the worker if the request it runs is no longer wanted, and drops such waiting ones.
    /// A measuring whose view moved on is ended too, and said to have stopped (the app
    /// measures the result again if it is still shown when the view rests).
    fn tick(&mut self) {
        self.retired.clear();
        if self.in_flight.as_ref().is_some_and(Request::is_stale) {
            self.end_worker();
        } else if self.in_flight.as_ref().is_some_and(Request::moved_on) {
            let request = self.in_flight.take();
            self.end_worker();
            if let Some(request) = request {
                on_measure_stopped(request);
            }
        }
        self.send_next();
    }
}

fn fail(request: Request, kind: JobKind, message: String) {
    let Sending { tx, ctx, ticket } = request.sending;
    let _ = tx.send((JobResult::JobFailed { kind, message }, ticket));
    ctx.request_repaint();
}

fn send(sending: Sending, result: JobResult) {
    let Sending { tx, ctx, ticket } = sending;
    // The receiver is gone only when the app closed; nothing left to tell.
    let _ = tx.send((result, ticket));
    ctx.request_repaint();
}

/// The engine's hierarchy: the page's copy of it, sent on as the desktop's job sends it.
fn on_hierarchy(request: Request, data: &JsValue) -> Option<Arc<Hierarchy>> {
    let Reply::Hierarchy {
        document,
        generation,
        mesh,
        ..
    } = request.reply
    else {
        return None;
    };
    let result = match text(data, "error") {
        Some(error) if error == HierarchyError::Cancelled.to_string() => {
            Err(HierarchyError::Cancelled)
        }
        Some(error) => Err(HierarchyError::Unsupported(
            error
                .strip_prefix("cannot build a hierarchy: ")
                .unwrap_or(&error)
                .to_owned(),
        )),
        None => {
            let bytes = get(data, "bytes")
                .dyn_ref::<js_sys::Uint8Array>()
                .map(js_sys::Uint8Array::to_vec)
                .unwrap_or_default();
            match Hierarchy::from_bytes(&bytes) {
                Ok(hierarchy) => {
                    let hierarchy = Arc::new(hierarchy);
                    let matches = get(data, "matches").is_truthy();
                    let sharp_edges = if matches {
                        SharpEdgeLines::new(&mesh, hierarchy.crease_edges())
                    } else {
                        SharpEdgeLines::default()
                    };
                    let denoise = text(data, "denoise")
                        .and_then(|json| serde_json::from_str::<serde_json::Value>(&json).ok())
                        .map(|json| DenoiseSummary {
                            report: report_from_json(&json["report"]),
                            time: Duration::from_secs_f64(
                                json["time_ms"].as_f64().unwrap_or(0.0).max(0.0) / 1e3,
                            ),
                        });
                    Ok(KeptHierarchy {
                        hierarchy,
                        build_time: Duration::from_secs_f64(
                            number(data, "build_ms").max(0.0) / 1e3,
                        ),
                        base_matches_original: matches,
                        sharp_edges: Arc::new(sharp_edges),
                        denoise,
                    })
                }
                Err(error) => Err(HierarchyError::Unsupported(error.to_string())),
            }
        }
    };
    let held = result.as_ref().ok().map(|kept| kept.hierarchy.clone());
    send(
        request.sending,
        JobResult::Hierarchy {
            document,
            hierarchy: generation,
            result,
        },
    );
    held
}

fn on_faired(request: Request, data: &JsValue) {
    let Reply::Fair {
        document,
        view,
        level,
        method,
    } = request.reply
    else {
        return;
    };
    let positions = get(data, "positions");
    let result = (!positions.is_undefined()).then(|| Faired {
        positions: positions_from(&positions),
        volume_change: number(data, "volume_change"),
        rms_displacement: number(data, "rms_displacement"),
        elapsed: Duration::from_secs_f64(number(data, "elapsed_ms").max(0.0) / 1e3),
        method,
        folds_left: number(data, "folds_left").max(0.0) as usize,
    });
    send(
        request.sending,
        JobResult::Faired {
            document,
            view,
            level,
            result,
        },
    );
}

/// The noisy mesh and its measures against the clean one, sent on as the desktop's io thread
/// sends them.
fn on_noised(request: Request, data: &JsValue) {
    let Reply::Noise {
        document,
        label,
        mesh,
        clean,
    } = &request.reply
    else {
        return;
    };
    let positions = positions_from(&get(data, "positions"));
    let vertices = mesh.positions.len();
    let against_clean = measures_from_js(&get(data, "against_clean"), vertices);
    let (Some(against_clean), true) = (against_clean, positions.len() == vertices) else {
        fail(
            request,
            JobKind::Noise,
            "the noisy mesh came back incomplete".into(),
        );
        return;
    };
    let result = JobResult::Noised {
        document: *document,
        label: label.clone(),
        noisy: Arc::new(TriMesh {
            positions,
            triangles: mesh.triangles.clone(),
        }),
        clean: clean.clone(),
        against_clean: Box::new(against_clean),
    };
    send(request.sending, result);
}

/// A measuring ended because its view moved on, said as the desktop's measuring thread says it.
fn on_measure_stopped(request: Request) {
    let Reply::Measure {
        document,
        serial,
        positions,
        ..
    } = request.reply
    else {
        return;
    };
    let result = JobResult::MeasureStopped {
        document,
        serial,
        positions,
    };
    send(request.sending, result);
}

/// A result's measures, sent on as the desktop's measuring thread sends them.
fn on_measured(request: Request, data: &JsValue) {
    let Reply::Measure {
        document,
        serial,
        ref positions,
        ..
    } = request.reply
    else {
        return;
    };
    let vertices = positions.len();
    let against_document = measures_from_js(&get(data, "against_document"), vertices);
    let clean = get(data, "against_clean");
    let against_clean = measures_from_js(&clean, vertices);
    if against_document.is_none() || (!clean.is_undefined() && against_clean.is_none()) {
        fail(
            request,
            JobKind::Measure,
            "the measures came back incomplete".into(),
        );
        return;
    }
    let result = JobResult::Measured {
        document,
        serial,
        against_document,
        against_clean,
        measure_time: Duration::from_secs_f64(number(data, "measure_ms").max(0.0) / 1e3),
    };
    send(request.sending, result);
}

/// What [`post_hierarchy`] needs.
pub(in crate::app) struct HierarchyPost {
    pub(in crate::app) settings: Settings,
    pub(in crate::app) mesh: Arc<TriMesh>,
    pub(in crate::app) file_edges: Vec<[u32; 2]>,
    pub(in crate::app) document: GenerationId,
    pub(in crate::app) document_generation: Generation,
    pub(in crate::app) generation: GenerationId,
    pub(in crate::app) hierarchy_generation: Generation,
    pub(in crate::app) progress: SharedProgress,
    pub(in crate::app) denoising: Arc<AtomicBool>,
}

/// Denoises and builds the hierarchy in the worker; `Err` (nothing sent, `sending` given back)
/// when there is no worker or the settings cannot go to it, and the caller runs the job on the
/// page.
pub(in crate::app) fn post_hierarchy(post: HierarchyPost, sending: Sending) -> Result<(), Sending> {
    let Some(message) = job_message("hierarchy", &post.settings) else {
        return Err(sending);
    };
    let transfer = js_sys::Array::new();
    set_mesh(&message, &transfer, "", &post.mesh);
    let edges: Vec<u32> = post.file_edges.iter().flatten().copied().collect();
    let edges = js_sys::Uint32Array::from(edges.as_slice());
    transfer.push(&edges.buffer());
    set(&message, "file_edges", edges);
    let request = Request {
        message,
        transfer,
        state: None,
        against: None,
        reply: Reply::Hierarchy {
            document: post.document,
            generation: post.generation,
            hierarchy_generation: post.hierarchy_generation,
            mesh: post.mesh,
            denoising: post.denoising,
        },
        document: post.document,
        document_generation: post.document_generation,
        progress: post.progress,
        sending,
    };
    queue(request, false)
}

/// What [`post_fair`] needs.
pub(in crate::app) struct FairPost {
    pub(in crate::app) settings: Settings,
    pub(in crate::app) hierarchy: Arc<Hierarchy>,
    pub(in crate::app) original: Arc<TriMesh>,
    pub(in crate::app) denoised: bool,
    pub(in crate::app) mask: Option<Mask>,
    pub(in crate::app) level: usize,
    pub(in crate::app) document: GenerationId,
    pub(in crate::app) document_generation: Generation,
    pub(in crate::app) view: GenerationId,
    pub(in crate::app) progress: SharedProgress,
}

/// Fairs from a level in the worker (see [`post_hierarchy`] for the error).
pub(in crate::app) fn post_fair(post: FairPost, sending: Sending) -> Result<(), Sending> {
    let Some(message) = job_message("fair", &post.settings) else {
        return Err(sending);
    };
    set(&message, "level", post.level as f64);
    let transfer = js_sys::Array::new();
    if let Some(mask) = &post.mask {
        let weights = js_sys::Float32Array::from(mask.weights());
        transfer.push(&weights.buffer());
        set(&message, "mask", weights);
    }
    let request = Request {
        message,
        transfer,
        state: Some(State {
            hierarchy: post.hierarchy,
            original: post.original,
            denoised: post.denoised,
        }),
        against: None,
        reply: Reply::Fair {
            document: post.document,
            view: post.view,
            level: post.level,
            method: post.settings.fairing.method,
        },
        document: post.document,
        document_generation: post.document_generation,
        progress: post.progress,
        sending,
    };
    queue(request, false)
}

/// Sets the levels up in the worker when nothing else waits (see [`post_hierarchy`]).
pub(in crate::app) fn post_prepare(
    settings: &Settings,
    state: (Arc<Hierarchy>, Arc<TriMesh>, bool),
    document: GenerationId,
    document_generation: Generation,
    sending: Sending,
) -> Result<(), Sending> {
    let Some(message) = job_message("prepare", settings) else {
        return Err(sending);
    };
    let (hierarchy, original, denoised) = state;
    let request = Request {
        message,
        transfer: js_sys::Array::new(),
        state: Some(State {
            hierarchy,
            original,
            denoised,
        }),
        against: None,
        reply: Reply::Prepare,
        document,
        document_generation,
        progress: SharedProgress::default(),
        sending,
    };
    queue(request, true)
}

/// What [`post_noise`] needs.
pub(in crate::app) struct NoisePost {
    pub(in crate::app) settings: Settings,
    pub(in crate::app) label: String,
    pub(in crate::app) mesh: Arc<TriMesh>,
    /// The mesh before any noise: `mesh` itself when it has none.
    pub(in crate::app) clean: Arc<TriMesh>,
    pub(in crate::app) document: GenerationId,
    pub(in crate::app) document_generation: Generation,
}

/// Adds noise to the document's mesh in the worker and measures it against the clean mesh
/// (see [`post_hierarchy`] for the error).
pub(in crate::app) fn post_noise(post: NoisePost, sending: Sending) -> Result<(), Sending> {
    let Some(message) = job_message("noise", &post.settings) else {
        return Err(sending);
    };
    let transfer = js_sys::Array::new();
    set_mesh(&message, &transfer, "", &post.mesh);
    if !Arc::ptr_eq(&post.clean, &post.mesh) {
        set_mesh(&message, &transfer, "clean_", &post.clean);
    }
    let request = Request {
        message,
        transfer,
        state: None,
        against: None,
        reply: Reply::Noise {
            document: post.document,
            label: post.label,
            mesh: post.mesh,
            clean: post.clean,
        },
        document: post.document,
        document_generation: post.document_generation,
        progress: SharedProgress::default(),
        sending,
    };
    queue(request, false)
}

/// What [`post_measure`] needs.
pub(in crate::app) struct MeasurePost {
    pub(in crate::app) document: GenerationId,
    pub(in crate::app) document_generation: Generation,
    pub(in crate::app) serial: u64,
    /// The faired result, on `base`'s triangles.
    pub(in crate::app) positions: Arc<Vec<[f32; 3]>>,
    /// The document's mesh.
    pub(in crate::app) base: Arc<TriMesh>,
    pub(in crate::app) clean: Option<Arc<TriMesh>>,
    pub(in crate::app) view_generation: Generation,
    /// The view the result is measured for.
    pub(in crate::app) view: GenerationId,
}

/// Measures a faired result against the document's mesh and the clean one in the measuring
/// worker, a worker of its own beside the engine's, so that a fairing never waits for a
/// measuring (see [`post_hierarchy`] for the error). The worker keeps the two meshes: a request
/// sends the result only. A newer measuring, or the view moving on (the slider, an option),
/// ends the worker, as the desktop stops its measuring half way; the next one starts afresh
/// and is sent the meshes again.
pub(in crate::app) fn post_measure(post: MeasurePost, sending: Sending) -> Result<(), Sending> {
    let message = js_sys::Object::new();
    set(&message, "kind", "measure");
    let transfer = js_sys::Array::new();
    let positions = flat_positions(&post.positions);
    transfer.push(&positions.buffer());
    set(&message, "positions", positions);
    let request = Request {
        message,
        transfer,
        state: None,
        against: Some(AgainstMeshes {
            base: post.base,
            clean: post.clean,
        }),
        reply: Reply::Measure {
            document: post.document,
            serial: post.serial,
            positions: post.positions,
            view_generation: post.view_generation,
            view: post.view,
        },
        document: post.document,
        document_generation: post.document_generation,
        progress: SharedProgress::default(),
        sending,
    };
    queue_on(Role::Measurer, request, false)
}

fn queue(request: Request, idle: bool) -> Result<(), Sending> {
    queue_on(Role::Engine, request, idle)
}

fn queue_on(role: Role, request: Request, idle: bool) -> Result<(), Sending> {
    role.with(|engine| {
        if engine.ensure_worker() {
            engine.queue(request, idle);
            Ok(())
        } else {
            Err(request.sending)
        }
    })
}

/// Whether the engine's worker (not the measuring one) runs a job now, and how many messages
/// the page has had from its workers so far: the page's status, which shows that the page
/// answers while a job runs (the count moves on between two of its frames).
pub(in crate::app) fn engine_activity() -> (bool, u64) {
    Role::Engine.with(|engine| (engine.in_flight.is_some(), engine.heard))
}

/// Once a frame: ends a worker when the job it runs is no longer wanted (Cancel, another
/// file, a measuring whose view moved on), and sends what waits.
pub(in crate::app) fn tick() {
    Role::Engine.with(Engine::tick);
    Role::Measurer.with(Engine::tick);
}
