// The page in a real browser (Debian's chromium through playwright-core), against the page
// served on 127.0.0.1 (scripts/test_web.sh builds, serves and calls this). Each check prints
// "ok" or "FAILED" with what it saw; the last line counts them ("N passed, N failed").
//
// Environment: FAIRMESH_WEB_URL (the page, ending in /), FAIRMESH_WEB_OUT (a folder for the
// screenshots, downloads and figures), FAIRMESH_WEB_BACKEND ("webgl2" asks the page for WebGL2
// alone; "webgpu" starts the browser with its software WebGPU, SwiftShader on Vulkan, and checks
// that the page draws through WebGPU; empty: the browser as before, with --disable-gpu, where it
// offers no WebGPU adapter and the page takes WebGL2), CHROMIUM (the browser, /usr/bin/chromium).
// The served folder holds the test files under data/ (scene.gltf with scene.bin and
// checker.png, textured.obj with textured.mtl and textured.png, broken.obj).

import { chromium } from "playwright-core";
import fs from "node:fs";
import path from "node:path";

const base = process.env.FAIRMESH_WEB_URL;
const out = process.env.FAIRMESH_WEB_OUT;
const backend = process.env.FAIRMESH_WEB_BACKEND || "";
const dataDir = process.env.FAIRMESH_WEB_DATA;
const tag = backend || "default";
fs.mkdirSync(out, { recursive: true });

let passed = 0;
let failed = 0;
const figures = {};
function check(name, ok, detail) {
  if (ok) passed++;
  else failed++;
  console.log(`${ok ? "ok" : "FAILED"} [${tag}] ${name}${detail ? ": " + detail : ""}`);
}

// Headless Chromium offers a WebGPU adapter only with --enable-unsafe-webgpu (SwiftShader's
// Vulkan); the page's canvas then reaches the screenshot only with ANGLE on SwiftShader too
// (docs/web.md lists what each flag gave).
const gpuArgs = backend === "webgpu"
  ? ["--enable-unsafe-webgpu", "--enable-features=Vulkan", "--use-vulkan=swiftshader", "--use-angle=swiftshader"]
  : ["--disable-gpu", "--enable-unsafe-swiftshader"];
const browser = await chromium.launch({
  executablePath: process.env.CHROMIUM || "/usr/bin/chromium",
  args: [
    "--no-sandbox", "--disable-quic", "--no-first-run",
    "--disable-background-networking", "--disable-component-update", "--disable-sync",
    ...gpuArgs,
  ],
});
const context = await browser.newContext({
  viewport: { width: 1280, height: 800 },
  acceptDownloads: true,
});
const page = await context.newPage();
const consoleErrors = [];
page.on("console", (message) => {
  if (message.type() === "error") consoleErrors.push(message.text());
});
page.on("pageerror", (error) => consoleErrors.push(String(error)));

const query = (extra) => {
  const params = new URLSearchParams(extra || {});
  if (backend === "webgl2") params.set("backend", backend);
  const text = params.toString();
  return base + (text ? "?" + text : "");
};

async function status() {
  return page.evaluate(() => {
    if (!window.fairmesh) return null;
    const text = window.fairmesh.status();
    return text ? JSON.parse(text) : null;
  });
}

// Waits until `wanted(status)` holds (and nothing is in flight, unless `unsettled`).
async function waitFor(what, wanted, timeoutMs = 120000, unsettled = false) {
  const started = Date.now();
  let last = null;
  while (Date.now() - started < timeoutMs) {
    last = await status();
    if (last && (unsettled || last.settled) && wanted(last)) return last;
    await page.waitForTimeout(100);
  }
  throw new Error(`timed out waiting for ${what}; last status: ${JSON.stringify(last)}`);
}

// The screenshot's pixels, counted in the page: how many differ from the 3D view's background
// (the colour at its corner) within the view, and how many of those are coloured (not grey).
async function shoot(name) {
  const file = path.join(out, `${tag}-${name}.png`);
  const png = await page.screenshot({ path: file });
  const stats = await page.evaluate(async (b64) => {
    const image = new Image();
    image.src = "data:image/png;base64," + b64;
    await image.decode();
    const canvas = document.createElement("canvas");
    canvas.width = image.width;
    canvas.height = image.height;
    const ctx = canvas.getContext("2d");
    ctx.drawImage(image, 0, 0);
    const { data, width, height } = ctx.getImageData(0, 0, image.width, image.height);
    // The 3D view fills the window left of the side panel (on the right): its middle.
    const x0 = Math.floor(width * 0.08), x1 = Math.floor(width * 0.6);
    const y0 = Math.floor(height * 0.15), y1 = Math.floor(height * 0.85);
    const at = (x, y) => { const i = (y * width + x) * 4; return [data[i], data[i + 1], data[i + 2]]; };
    // The background: the commonest colour of the region's border.
    const counts = new Map();
    for (let x = x0; x < x1; x += 4) {
      for (const y of [y0, y1 - 1]) {
        const key = at(x, y).join(",");
        counts.set(key, (counts.get(key) || 0) + 1);
      }
    }
    const background = [...counts.entries()].sort((a, b) => b[1] - a[1])[0][0].split(",").map(Number);
    let mesh = 0, coloured = 0, total = 0;
    const pixels = [];
    for (let y = y0; y < y1; y += 2) {
      for (let x = x0; x < x1; x += 2) {
        const [r, g, b] = at(x, y);
        total++;
        pixels.push(r, g, b);
        const d = Math.abs(r - background[0]) + Math.abs(g - background[1]) + Math.abs(b - background[2]);
        if (d > 24) {
          mesh++;
          if (Math.max(r, g, b) - Math.min(r, g, b) > 40) coloured++;
        }
      }
    }
    return { mesh: mesh / total, coloured: coloured / total, background, pixels };
  }, png.toString("base64"));
  return stats;
}

// The share of the view's pixels that differ between two screenshots (by more than 8 in the sum
// of the three channels: the same image drawn again is the same to the bit, and a slider step's
// change of shading is gentle, most of it under the 24 that tells mesh from background).
function difference(a, b) {
  let changed = 0;
  for (let i = 0; i < a.pixels.length; i += 3) {
    const d = Math.abs(a.pixels[i] - b.pixels[i]) + Math.abs(a.pixels[i + 1] - b.pixels[i + 1]) +
      Math.abs(a.pixels[i + 2] - b.pixels[i + 2]);
    if (d > 8) changed++;
  }
  return changed / (a.pixels.length / 3);
}

async function command(name, value) {
  await page.evaluate(([n, v]) => window.fairmesh.command(n, v), [name, String(value)]);
}

try {
  // 1. The bunny on start, shaded.
  const loadStarted = Date.now();
  await page.goto(query());
  await waitFor("the bunny loaded", (s) => s.document, 60000, true);
  figures.bunny_loaded_ms = Date.now() - loadStarted;
  const first = await waitFor("the first picture", (s) => s.document && s.images_drawn > 0, 60000, true);
  // When status() first showed the picture (a frame after the browser showed it); the page's
  // mark fairmesh_first_picture below is when the browser showed it.
  figures.first_picture_status_ms = Date.now() - loadStarted;
  // The loading job itself (reading the file, welding, the connectivity).
  figures.bunny_load_job_ms = first.load_ms === undefined ? null : Math.round(first.load_ms);
  // Where the time to the first picture goes (marks set by index.html).
  for (const mark of await page.evaluate(() => performance.getEntriesByType("mark").map((m) => [m.name, m.startTime]))) {
    figures[`${mark[0]}_ms`] = Math.round(mark[1]);
  }
  // From the page's start (the navigation) to the first picture shown.
  figures.first_picture_ms = figures.fairmesh_first_picture_ms ?? null;
  let s = await waitFor("the bunny's hierarchy", (s) => s.hierarchy_ready && s.shown_serial !== null);
  figures.bunny_ready_ms = Date.now() - loadStarted;
  const bunny = await shoot("bunny");
  check("the bunny is shown", s.document.endsWith("bunny00.obj") && bunny.mesh > 0.05,
    `${s.document}, ${(bunny.mesh * 100).toFixed(1)}% of the view is mesh, first picture ${figures.first_picture_ms} ms after the page's start`);
  figures.adapter = s.adapter;
  figures.samples = s.samples;
  const webgpu = await page.evaluate(() => !!navigator.gpu);
  if (backend === "webgl2") {
    check("WebGL2 alone draws it", /\(gl\)$/i.test(s.adapter || ""), `adapter: ${s.adapter}`);
  } else if (backend === "webgpu") {
    check("WebGPU draws it", /\(BrowserWebGpu\)$/.test(s.adapter || ""), `adapter: ${s.adapter}`);
  } else {
    console.log(`[${tag}] navigator.gpu ${webgpu ? "present" : "absent"}; adapter: ${s.adapter}`);
  }
  // Every pass here draws on SwiftShader (WebGL2 through ANGLE, or WebGPU on its Vulkan): a
  // software renderer, which the page draws with one sample (no anti-aliasing).
  check("the software renderer draws with one sample", s.samples === 1,
    `${s.samples} samples per pixel, adapter: ${s.adapter}`);

  // 2. A slider step changes the picture.
  const level = Math.min(2, s.level_count - 1);
  const before = await shoot("bunny-level-before");
  await command("level", level);
  s = await waitFor(`level ${level}`, (s) => s.faired_level === level && s.shown_serial === s.faired_serial);
  const after = await shoot(`bunny-level-${level}`);
  const changed = difference(before, after);
  check("a slider step changes the picture", s.level === level && changed > 0.002,
    `level ${s.level}, ${(changed * 100).toFixed(2)}% of the view's pixels changed`);

  // 3. A glTF through ?open= with its .bin and texture beside it, in its own colours.
  await page.goto(query({ open: "data/scene.gltf" }));
  s = await waitFor("scene.gltf", (s) => s.document && s.document.endsWith("scene.gltf") && s.hierarchy_ready);
  const scene = await shoot("scene-gltf");
  check("?open= shows a glTF in its colours", scene.mesh > 0.02 && scene.coloured > 0.01 && !s.error,
    `${(scene.mesh * 100).toFixed(1)}% mesh, ${(scene.coloured * 100).toFixed(1)}% coloured, warnings ${JSON.stringify(s.warnings)}, error ${s.error}`);

  // 4. An OBJ with its .mtl and texture through the file input, then a slider step and Export.
  await page.setInputFiles("#fairmesh-file-input", ["textured.obj", "textured.mtl", "textured.png"].map((f) => path.join(dataDir, f)));
  s = await waitFor("textured.obj", (s) => s.document && s.document.endsWith("textured.obj") && s.hierarchy_ready);
  const textured = await shoot("textured-obj");
  check("the file input shows an OBJ in its texture", textured.mesh > 0.02 && textured.coloured > 0.01 && !s.error,
    `${(textured.mesh * 100).toFixed(1)}% mesh, ${(textured.coloured * 100).toFixed(1)}% coloured, error ${s.error}`);
  const exportLevel = Math.min(2, s.level_count - 1);
  await command("level", exportLevel);
  s = await waitFor(`level ${exportLevel} of textured.obj`, (s) => s.faired_level === exportLevel && s.shown_serial === s.faired_serial);
  const download = page.waitForEvent("download", { timeout: 60000 });
  await command("export", "textured_faired.obj");
  const file = await download;
  const saved = path.join(out, `${tag}-${file.suggestedFilename()}`);
  await file.saveAs(saved);
  check("Export downloads the OBJ with its .mtl and texture as a .zip", file.suggestedFilename() === "textured_faired.zip",
    `${file.suggestedFilename()} (${fs.statSync(saved).size} bytes); compared with the CLI by test_web.sh`);
  // Export levels: the level chain, every level as a GLB, in one .zip (compared with the CLI's
  // `hierarchy --write-levels` by check_downloads.py).
  const levelsDownload = page.waitForEvent("download", { timeout: 60000 });
  await command("export_levels", "");
  const levelsFile = await levelsDownload;
  const levelsSaved = path.join(out, `${tag}-${levelsFile.suggestedFilename()}`);
  await levelsFile.saveAs(levelsSaved);
  s = await waitFor("the level chain's message", (s) => s.message && s.message.startsWith("Exported"));
  fs.writeFileSync(path.join(out, `${tag}-export.json`), JSON.stringify({ file: saved, level: exportLevel, levels: levelsSaved, level_count: s.level_count }));
  check("Export levels downloads every level as a GLB in one .zip", levelsFile.suggestedFilename() === "textured_levels.zip" && !s.error,
    `${levelsFile.suggestedFilename()} (${fs.statSync(levelsSaved).size} bytes), "${s.message}"`);

  // 5. A broken file: the same error as native, and the page goes on.
  await page.setInputFiles("#fairmesh-file-input", [path.join(dataDir, "broken.obj")]);
  s = await waitFor("the broken file's error", (s) => s.error !== null);
  fs.writeFileSync(path.join(out, `${tag}-broken-error.txt`), s.error);
  await shoot("broken");
  const stillThere = s.document && s.document.endsWith("textured.obj");
  await command("level", 0);
  s = await waitFor("level 0 after the error", (s) => s.faired_level === 0 && s.shown_serial === s.faired_serial);
  check("a broken file shows its error and the page goes on", stillThere && s.level === 0,
    `error "${fs.readFileSync(path.join(out, `${tag}-broken-error.txt`), "utf8")}"`);

  // 5b. Files dropped on the page: a glTF with its .bin and texture, dropped together (the
  // browser's drop event with a DataTransfer of the files, as a file manager gives it).
  const dropped = ["scene.gltf", "scene.bin", "checker.png"].map((f) =>
    [f, fs.readFileSync(path.join(dataDir, f)).toString("base64")]);
  await page.evaluate((files) => {
    const transfer = new DataTransfer();
    for (const [name, b64] of files) {
      const bytes = Uint8Array.from(atob(b64), (c) => c.charCodeAt(0));
      transfer.items.add(new File([bytes], name));
    }
    const canvas = document.getElementById("fairmesh-canvas");
    for (const type of ["dragenter", "dragover", "drop"]) {
      canvas.dispatchEvent(new DragEvent(type, { dataTransfer: transfer, bubbles: true, cancelable: true }));
    }
  }, dropped);
  s = await waitFor("the dropped scene.gltf", (s) => s.document && s.document.endsWith("scene.gltf") && s.hierarchy_ready);
  const droppedShot = await shoot("dropped-gltf");
  check("files dropped on the page open together, in their colours", droppedShot.mesh > 0.02 && droppedShot.coloured > 0.01 && !s.error,
    `${(droppedShot.mesh * 100).toFixed(1)}% mesh, ${(droppedShot.coloured * 100).toFixed(1)}% coloured, warnings ${JSON.stringify(s.warnings)}, error ${s.error}`);

  // 6. The page answers while the long jobs run in the engine's worker: after Add noise, the noise,
  // the noisy bunny's default fair (the denoise before the hierarchy), the hierarchy and the
  // fairing. What is checked is that the page's thread is not blocked while the worker runs: the
  // page goes on drawing frames, and the status() calls are answered between them. A frame counts
  // when its answer shows the engine's worker running a job *and* a later answer, from another
  // frame, shows it still running with more messages heard from it: the worker went on working
  // after that frame was drawn (the job did not finish within it). On the page's own thread
  // (?worker=0) a job runs within one frame, between two answers, and there is no worker to hear
  // from, so no frame can count (that run checks it: the count tells the two apart). One such
  // frame is the proof wanted: the page drew it and answered while the worker went on working.
  // No count of frames or time is asked for beyond it, because how many frames fit in the jobs
  // depends on the machine: on a loaded 2-core machine the software GPU takes 1-3 s a frame,
  // about as long as the noisy bunny's denoise and hierarchy in the worker.
  // Figures: the longest status() call, the longest gap between frames and the longest task the
  // browser reported (PerformanceObserver "longtask"), from Add noise to the faired result on
  // screen; then (worker only) the time from a slider step to its picture while the result
  // before it is being measured, and the same with no measuring in flight.
  const answeredWanted = 1;
  for (const mode of ["worker", "page"]) {
    await page.goto(query(mode === "page" ? { worker: "0" } : {}));
    s = await waitFor("the bunny again", (s) => s.document && s.document.endsWith("bunny00.obj") && s.hierarchy_ready);
    await page.evaluate(() => {
      window.fairmeshLongestFrameGap = 0;
      window.fairmeshLongestTask = 0;
      let last = performance.now();
      const tick = (now) => {
        window.fairmeshLongestFrameGap = Math.max(window.fairmeshLongestFrameGap, now - last);
        last = now;
        requestAnimationFrame(tick);
      };
      requestAnimationFrame(tick);
      new PerformanceObserver((list) => {
        for (const entry of list.getEntries()) {
          window.fairmeshLongestTask = Math.max(window.fairmeshLongestTask, entry.duration);
        }
      }).observe({ type: "longtask" });
    });
    const clean = s;
    const noiseStarted = Date.now();
    await command("noise", "");
    // The answers given while the engine's worker ran a job, in order.
    const inFlight = [];
    let longestCall = 0;
    let samples = 0;
    const done = (s) => s && s.settled && s.hierarchy_ready && s.denoise_ms !== null && s.denoise_ms !== clean.denoise_ms &&
      s.faired_serial !== clean.faired_serial && s.shown_serial === s.faired_serial;
    for (;;) {
      const asked = Date.now();
      s = await status();
      longestCall = Math.max(longestCall, Date.now() - asked);
      samples++;
      if (s && s.engine_busy) inFlight.push({ frame: s.frame, heard: s.engine_heard });
      if (done(s)) break;
      if (Date.now() - noiseStarted > 180000) throw new Error(`the noisy bunny's result did not arrive: ${JSON.stringify(s)}`);
      await page.waitForTimeout(50);
    }
    // The frames after which the worker was heard from again, still running a job.
    const answered = new Set();
    inFlight.forEach((answer, i) => {
      if (inFlight.slice(i + 1).some((later) => later.frame !== answer.frame && later.heard > answer.heard)) {
        answered.add(answer.frame);
      }
    });
    const inFlightFrames = new Set(inFlight.map((answer) => answer.frame)).size;
    const key = mode === "worker" ? "" : "_on_page";
    figures[`noisy_bunny_default_fair_ms${key}`] = s.denoise_ms;
    figures[`noisy_bunny_hierarchy_ms${key}`] = s.hierarchy_ms;
    figures[`noisy_bunny_to_result_ms${key}`] = Date.now() - noiseStarted;
    figures[`longest_status_call_ms${key}`] = longestCall;
    figures[`longest_frame_gap_ms${key}`] = await page.evaluate(() => window.fairmeshLongestFrameGap);
    figures[`longest_task_ms${key}`] = await page.evaluate(() => window.fairmeshLongestTask);
    figures[`frames_answered_while_running${key}`] = answered.size;
    const detail = `${answered.size} frames answered with the worker still running after them (${inFlightFrames} frames showed it running, ${samples} status() calls; longest call ${longestCall} ms)`;
    if (mode === "worker") {
      check("the page answers while the noise, denoise, hierarchy and fairing run in the worker, and the result arrives",
        answered.size >= answeredWanted && s.shown_serial === s.faired_serial, detail);
      await shoot("noisy-bunny-faired");

      // A slider step right after a result, while that result is being measured: the step's
      // fairing does not wait for the measuring (figures only). A build whose status() does not
      // say "measuring" gets the measuring's 100 ms delay and a little more instead.
      const levels = [2, 3, 4].filter((l) => l !== s.faired_level && l < s.level_count);
      await command("level", levels[0]);
      await waitFor(`level ${levels[0]}`, (s) => s.faired_level === levels[0] && s.shown_serial === s.faired_serial, 120000, true);
      if ("measuring" in s) {
        await waitFor("its measuring", (s) => s.measuring, 60000, true);
      } else {
        await page.waitForTimeout(400);
      }
      const measuringAtStep = (await status()).measuring;
      let stepped = Date.now();
      await command("level", levels[1]);
      await waitFor(`level ${levels[1]} during a measuring`, (s) => s.faired_level === levels[1] && s.shown_serial === s.faired_serial, 120000, true);
      figures.slider_step_with_measuring_ms = Date.now() - stepped;
      figures.measuring_at_step = measuringAtStep === undefined ? null : measuringAtStep;
      // The same step with nothing in flight.
      await waitFor("everything settled", () => true);
      stepped = Date.now();
      await command("level", levels[0]);
      await waitFor(`level ${levels[0]} again`, (s) => s.faired_level === levels[0] && s.shown_serial === s.faired_serial, 120000, true);
      figures.slider_step_quiet_ms = Date.now() - stepped;
      await waitFor("its measures", () => true);
    } else {
      check("on the page's thread (?worker=0) no frame counts (the check tells the two apart)",
        answered.size === 0, detail);
    }
  }
  console.log(`figures [${tag}]: ${JSON.stringify(figures)}`);

  // 7. Settings are remembered in the browser's storage.
  const stored = await page.evaluate(() => Object.keys(window.localStorage));
  check("settings are kept in the browser's storage", stored.length > 0, JSON.stringify(stored));
} catch (error) {
  check("the run", false, String(error && error.stack || error));
  await page.screenshot({ path: path.join(out, `${tag}-failure.png`) }).catch(() => {});
}

check("the console has no error or panic", consoleErrors.length === 0, consoleErrors.slice(0, 5).join(" | "));
fs.writeFileSync(path.join(out, `${tag}-figures.json`), JSON.stringify(figures));
await browser.close();
console.log(`${passed} passed, ${failed} failed`);
process.exit(failed === 0 ? 0 : 1);
