//! `?open=URL`: a mesh fetched from its URL (same origin, or a server that allows it), with the
//! files it names beside it: a glTF's external buffers and images, an OBJ's `.mtl` libraries
//! and the images they name. A companion that cannot be fetched is left out; the library then
//! names it in its warning, as for a file missing beside a file on disk.

use wasm_bindgen::JsCast;
use wasm_bindgen_futures::JsFuture;

use super::events::{describe, extension, open_files, push, WebEvent};

/// `relative` resolved against `base` (both URLs, `base` absolute).
fn resolve(relative: &str, base: &str) -> Result<String, String> {
    web_sys::Url::new_with_base(relative, base)
        .map(|url| url.href())
        .map_err(|error| format!("{relative}: not a valid URL ({})", describe(&error)))
}

/// The body the page fetched ahead for `url` (`index.html` fetches the bunny while the module
/// compiles: `window.fairmeshPrefetch = {url, body}`, `body` a promise of an `ArrayBuffer`), if
/// it did and the fetch went well; taken once.
async fn prefetched(url: &str) -> Option<Vec<u8>> {
    let window = web_sys::window()?;
    let key = wasm_bindgen::JsValue::from_str("fairmeshPrefetch");
    let ahead = js_sys::Reflect::get(&window, &key).ok()?;
    let ahead_url = js_sys::Reflect::get(&ahead, &"url".into())
        .ok()?
        .as_string()?;
    if ahead_url != url {
        return None;
    }
    let _ = js_sys::Reflect::delete_property(&window, &key);
    let body = js_sys::Reflect::get(&ahead, &"body".into()).ok()?;
    let body = JsFuture::from(body.dyn_into::<js_sys::Promise>().ok()?)
        .await
        .ok()?;
    body.is_instance_of::<js_sys::ArrayBuffer>()
        .then(|| js_sys::Uint8Array::new(&body).to_vec())
}

/// The body of `url`, or why not.
async fn fetch_bytes(url: &str) -> Result<Vec<u8>, String> {
    // A fetch the page made ahead that failed is made again here, to say why.
    if let Some(bytes) = prefetched(url).await {
        return Ok(bytes);
    }
    let window = web_sys::window().ok_or("no browser window")?;
    let response = JsFuture::from(window.fetch_with_str(url))
        .await
        .map_err(|error| format!("{url} could not be fetched ({})", describe(&error)))?;
    let response: web_sys::Response = response
        .dyn_into()
        .map_err(|_| format!("{url}: the answer is not a response"))?;
    if !response.ok() {
        return Err(format!(
            "{url}: the server answered {} {}",
            response.status(),
            response.status_text()
        ));
    }
    let body = response
        .array_buffer()
        .map_err(|error| format!("{url}: the body cannot be read ({})", describe(&error)))?;
    let body = JsFuture::from(body)
        .await
        .map_err(|error| format!("{url}: the body cannot be read ({})", describe(&error)))?;
    Ok(js_sys::Uint8Array::new(&body).to_vec())
}

/// The relative file names a glTF's JSON refers to (buffers and images that are not data: URIs).
fn gltf_companions(json: &[u8]) -> Vec<String> {
    let Ok(document) = serde_json::from_slice::<serde_json::Value>(json) else {
        return Vec::new();
    };
    ["buffers", "images"]
        .iter()
        .filter_map(|key| document.get(key)?.as_array())
        .flatten()
        .filter_map(|entry| entry.get("uri")?.as_str())
        .filter(|uri| !uri.starts_with("data:"))
        .map(str::to_owned)
        .collect()
}

/// What follows `keyword` on the lines of a text that start with it, each once.
fn named_after(text: &[u8], keywords: &[&str]) -> Vec<String> {
    let text = String::from_utf8_lossy(text);
    let mut names: Vec<String> = Vec::new();
    for line in text.lines() {
        let mut words = line.split_whitespace();
        let Some(first) = words.next() else { continue };
        if !keywords.contains(&first)
            && !keywords
                .iter()
                .any(|k| k.ends_with('_') && first.starts_with(k))
        {
            continue;
        }
        // `mtllib` names the rest of the line; a map line's options come first, the file last.
        let name = if first == "mtllib" {
            line.trim_start()[first.len()..].trim().to_owned()
        } else {
            words.last().unwrap_or_default().to_owned()
        };
        let name = name.replace('\\', "/");
        if !name.is_empty() && !names.contains(&name) {
            names.push(name);
        }
    }
    names
}

/// The file name a URI stands for in the folder (percent codes decoded, as the loaders read it).
fn local_name(uri: &str) -> String {
    js_sys::decode_uri_component(uri)
        .map(String::from)
        .unwrap_or_else(|_| uri.to_owned())
}

/// Fetches `url` (relative to the page, or absolute) and what it names beside it, then opens it.
pub fn open_url(url: String) {
    wasm_bindgen_futures::spawn_local(async move {
        match fetch_with_companions(&url).await {
            Ok(files) => {
                super::mark("fairmesh_fetched");
                open_files(files, "the fetched files");
            }
            Err(error) => push(WebEvent::Failed(error)),
        }
    });
}

async fn fetch_with_companions(url: &str) -> Result<Vec<(String, Vec<u8>)>, String> {
    let page = web_sys::window()
        .and_then(|w| w.location().href().ok())
        .ok_or("no page address")?;
    let absolute = resolve(url, &page)?;
    let bytes = fetch_bytes(&absolute).await?;
    let path = web_sys::Url::new(&absolute)
        .map(|u| u.pathname())
        .unwrap_or_default();
    let name = local_name(path.rsplit('/').next().unwrap_or("mesh"));
    let mut wanted = match extension(&name).as_str() {
        "gltf" => gltf_companions(&bytes),
        "obj" => named_after(&bytes, &["mtllib"]),
        _ => Vec::new(),
    };
    let mut files = vec![(name, bytes)];
    // Breadth first: an OBJ's libraries, then the images the libraries name.
    let mut next = 0;
    while next < wanted.len() {
        let relative = wanted[next].clone();
        next += 1;
        let Ok(companion) = resolve(&relative, &absolute) else {
            continue;
        };
        let Ok(bytes) = fetch_bytes(&companion).await else {
            continue;
        };
        if extension(&relative) == "mtl" {
            let folder = relative.rsplit_once('/').map(|(folder, _)| folder);
            for image in named_after(&bytes, &["map_", "bump", "norm", "disp", "decal", "refl"]) {
                let image = match folder {
                    Some(folder) => format!("{folder}/{image}"),
                    None => image,
                };
                if !wanted.contains(&image) {
                    wanted.push(image);
                }
            }
        }
        files.push((local_name(&relative), bytes));
    }
    Ok(files)
}
