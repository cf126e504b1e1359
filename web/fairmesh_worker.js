// The page's workers (the engine, and the measuring worker beside it): each runs the same module
// as the page (fairmesh_web.js), so that denoising, building the hierarchy, fairing and measuring
// leave the page free to answer. The page posts requests; the module answers each with
// postMessage (editor: app/web/engine.rs).
import init, { engine_handle } from "./fairmesh_web.js";

let ready = null;
self.onmessage = (event) => {
  const message = event.data;
  if (message && message.kind === "init") {
    // The module the page compiled, when it passed one (else it is fetched beside this file).
    ready = init(message.module ? { module_or_path: message.module } : undefined);
    return;
  }
  if (ready === null) {
    ready = init();
  }
  // One request after the other, in the order they came.
  ready = ready.then(() => engine_handle(message)).catch((error) => {
    self.postMessage({ kind: "failed", message: String(error && error.message || error) });
  });
};
