//! A file handed to the browser as a download: a `Blob` behind an `<a download>` link, clicked.

use std::cell::RefCell;

use wasm_bindgen::JsCast;

use super::events::describe;

thread_local! {
    /// The previous download's object URL, released at the next one (the browser may still be
    /// reading it right after the click).
    static LAST_URL: RefCell<Option<String>> = const { RefCell::new(None) };
}

/// Offers `bytes` for download as `name`.
pub(super) fn offer(name: &str, bytes: &[u8]) -> Result<(), String> {
    let failed = |error: wasm_bindgen::JsValue| {
        format!("{name}: the download failed ({})", describe(&error))
    };
    let document = web_sys::window()
        .and_then(|w| w.document())
        .ok_or_else(|| format!("{name}: no page to download from"))?;
    let parts = js_sys::Array::of1(&js_sys::Uint8Array::from(bytes));
    let options = web_sys::BlobPropertyBag::new();
    options.set_type("application/octet-stream");
    let blob =
        web_sys::Blob::new_with_u8_array_sequence_and_options(&parts, &options).map_err(failed)?;
    let url = web_sys::Url::create_object_url_with_blob(&blob).map_err(failed)?;
    let link: web_sys::HtmlAnchorElement = document
        .create_element("a")
        .map_err(failed)?
        .dyn_into()
        .map_err(|_| format!("{name}: no link element"))?;
    link.set_href(&url);
    link.set_download(name);
    link.click();
    if let Some(previous) = LAST_URL.with(|last| last.borrow_mut().replace(url)) {
        let _ = web_sys::Url::revoke_object_url(&previous);
    }
    Ok(())
}
