//! The page's start: the canvas, the renderer's set-up, the app, and the `?open=` parameter.

use fairmesh_editor::app::{web, App, AppOptions};
use wasm_bindgen::prelude::*;

/// The id of the canvas the editor draws on (`web/index.html`).
const CANVAS_ID: &str = "fairmesh-canvas";

/// The page's query parameter `name`, if given.
fn query_parameter(name: &str) -> Option<String> {
    let search = web_sys::window()?.location().search().ok()?;
    web_sys::UrlSearchParams::new_with_str(&search)
        .ok()?
        .get(name)
        .filter(|value| !value.is_empty())
}

/// Shows `message` in the page's loading line (the editor could not start).
fn show_failure(message: &str) {
    let element = web_sys::window()
        .and_then(|w| w.document())
        .and_then(|d| d.get_element_by_id("fairmesh-loading"));
    if let Some(element) = element {
        element.set_text_content(Some(message));
    }
}

/// Runs when the page loads the module: starts the editor on the canvas (in the engine's
/// worker, which has no page, it only sets the panic hook).
#[wasm_bindgen(start)]
pub fn start() {
    // Panics and the editor's log go to the browser's console.
    std::panic::set_hook(Box::new(|info| {
        let message = format!("fairmesh panicked: {info}");
        web_sys::console::error_1(&message.clone().into());
        show_failure(&message);
    }));
    if web_sys::window().is_none() {
        return;
    }
    let Some(canvas) = web_sys::window()
        .and_then(|w| w.document())
        .and_then(|d| d.get_element_by_id(CANVAS_ID))
        .and_then(|e| e.dyn_into::<web_sys::HtmlCanvasElement>().ok())
    else {
        show_failure("The page has no canvas to draw on");
        return;
    };
    let mut wgpu_options = fairmesh_editor::app::wgpu_configuration();
    if query_parameter("backend").as_deref() == Some("webgl2") {
        if let egui_wgpu::WgpuSetup::CreateNew(setup) = &mut wgpu_options.wgpu_setup {
            setup.instance_descriptor.backends = wgpu::Backends::GL;
        }
    }
    let options = eframe::WebOptions {
        wgpu_options,
        ..Default::default()
    };
    let open = query_parameter("open");
    let webgl2 = query_parameter("backend").as_deref() == Some("webgl2");
    wasm_bindgen_futures::spawn_local(async move {
        // index.html asks the browser's WebGPU adapter whether it is a software renderer while
        // the module compiles (wgpu's adapter info does not say): answered by now.
        if !webgl2 {
            fairmesh_editor::render::page::set_software_webgpu(software_webgpu().await);
        }
        let started = eframe::WebRunner::new()
            .start(
                canvas,
                options,
                Box::new(move |cc| {
                    web::mark("fairmesh_runner_ready");
                    web::listen_to_file_input();
                    let app = App::with_options(
                        cc,
                        AppOptions {
                            persistence: true,
                            ..AppOptions::default()
                        },
                    );
                    if let Some(url) = open {
                        web::open_url(url);
                    }
                    Ok(Box::new(app))
                }),
            )
            .await;
        match started {
            Ok(()) => {
                if let Some(element) = web_sys::window()
                    .and_then(|w| w.document())
                    .and_then(|d| d.get_element_by_id("fairmesh-loading"))
                {
                    element.remove();
                }
            }
            Err(error) => show_failure(&format!("The editor could not start: {error:?}")),
        }
    });
}

/// Whether `window.fairmeshSoftwareWebGpu` (index.html: a promise of whether the browser's
/// WebGPU adapter is a software renderer, SwiftShader or the fallback adapter) says so.
async fn software_webgpu() -> bool {
    let Some(window) = web_sys::window() else {
        return false;
    };
    let Ok(answer) = js_sys::Reflect::get(&window, &JsValue::from_str("fairmeshSoftwareWebGpu"))
    else {
        return false;
    };
    let Ok(promise) = answer.dyn_into::<js_sys::Promise>() else {
        return false;
    };
    wasm_bindgen_futures::JsFuture::from(promise)
        .await
        .is_ok_and(|software| software.as_bool() == Some(true))
}

/// What the editor showed at the end of its last frame, as JSON (`window.fairmesh.status()`:
/// the document, whether work is in flight, the levels, the result on screen, the error).
#[wasm_bindgen]
pub fn status() -> String {
    web::status()
}

/// Asks the editor for something as its widgets would (`window.fairmesh.command(name, value)`):
/// `level` N, `export` NAME, `open` URL, `noise`, `undo`, `redo`, `fit`.
///
/// # Errors
/// An unknown command or a value that is not what the command takes.
#[wasm_bindgen]
pub fn command(name: &str, value: &str) -> Result<(), JsValue> {
    web::command(name, value).map_err(|error| JsValue::from_str(&error))
}

/// The engine's answer to one request from the page: `fairmesh_worker.js`, the Web Worker that
/// runs this module beside the page, calls it for each message (the hierarchy and fairing run
/// there, so that the page goes on answering).
#[wasm_bindgen]
pub fn engine_handle(message: JsValue) {
    web::engine::handle(message);
}
