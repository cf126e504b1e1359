//! The files the page gives (picked, dropped, fetched), each set put in a memory folder of its
//! own, and what the asynchronous work found, waiting for the next frame ([`take`]).

use std::cell::RefCell;
use std::path::{Path, PathBuf};

use fairmesh::io::MemoryFolder;
use wasm_bindgen::JsCast;

/// What the page's asynchronous work found, for the next frame.
pub(super) enum WebEvent {
    /// Open the mesh file at this path (in a memory folder).
    Open(PathBuf),
    /// Show this error (the page goes on).
    Failed(String),
    /// Carry out a command, as if a widget had emitted it (the page's scripting hook).
    Command(crate::app::Command),
}

thread_local! {
    static PENDING: RefCell<Vec<WebEvent>> = const { RefCell::new(Vec::new()) };
    /// The folders of the files given so far: kept, because an earlier document (undo) may
    /// still read its textures from its folder when exported.
    static FOLDERS: RefCell<Vec<MemoryFolder>> = const { RefCell::new(Vec::new()) };
    /// What the app showed at the end of its last frame, as JSON (`App::publish_status`).
    pub(super) static STATUS: RefCell<String> = const { RefCell::new(String::new()) };
    /// Set by `App::poll_web` so that the asynchronous work can wake the page.
    static CONTEXT: RefCell<Option<egui::Context>> = const { RefCell::new(None) };
}

pub(super) fn push(event: WebEvent) {
    PENDING.with(|pending| pending.borrow_mut().push(event));
    CONTEXT.with(|ctx| {
        if let Some(ctx) = ctx.borrow().as_ref() {
            ctx.request_repaint();
        }
    });
}

/// The mesh formats by preference, when several files are given together (a `.gltf` over the
/// `.obj` it may have been converted from, say).
const MESH_EXTENSIONS: [&str; 6] = ["gltf", "glb", "obj", "ply", "stl", "off"];

pub(super) fn extension(name: &str) -> String {
    Path::new(name)
        .extension()
        .map(|e| e.to_string_lossy().to_ascii_lowercase())
        .unwrap_or_default()
}

/// A 64-bit FNV-1a hash: names a folder by its mesh file's content.
fn content_hash(bytes: &[u8]) -> u64 {
    bytes.iter().fold(0xcbf2_9ce4_8422_2325, |hash, &byte| {
        (hash ^ u64::from(byte)).wrapping_mul(0x0000_0100_0000_01b3)
    })
}

/// Puts `files` (names relative to one folder, with their bytes) in a memory folder of their own
/// and queues the opening of its mesh file; `from` says where they came from, for the error
/// when none is a mesh.
pub(super) fn open_files(files: Vec<(String, Vec<u8>)>, from: &str) {
    let mesh = MESH_EXTENSIONS.iter().find_map(|wanted| {
        files
            .iter()
            .find(|(name, _)| extension(name) == *wanted)
            .map(|(name, bytes)| (name.clone(), content_hash(bytes)))
    });
    let Some((mesh_name, hash)) = mesh else {
        let names: Vec<&str> = files.iter().map(|(name, _)| name.as_str()).collect();
        push(WebEvent::Failed(format!(
            "{}: no mesh file among {from} (the editor opens .obj, .gltf, .glb, .ply, .stl and .off)",
            names.join(", ")
        )));
        return;
    };
    let folder = MemoryFolder::new(format!("/web/{hash:016x}"));
    for (name, bytes) in files {
        folder.insert(&name, bytes);
    }
    let path = folder.path(&mesh_name);
    FOLDERS.with(|folders| folders.borrow_mut().push(folder));
    push(WebEvent::Open(path));
}

/// The events since the last call; `ctx` is woken by later ones.
pub(super) fn take(ctx: &egui::Context) -> Vec<WebEvent> {
    CONTEXT.with(|context| {
        context.borrow_mut().get_or_insert_with(|| ctx.clone());
    });
    PENDING.with(|pending| std::mem::take(&mut *pending.borrow_mut()))
}

/// What a JavaScript error value says, in words.
pub(super) fn describe(error: &wasm_bindgen::JsValue) -> String {
    error
        .dyn_ref::<js_sys::Error>()
        .map(|e| String::from(e.message()))
        .or_else(|| error.as_string())
        .unwrap_or_else(|| format!("{error:?}"))
}
