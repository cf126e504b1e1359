// Validates glTF/GLB files with the Khronos glTF validator (npm package `gltf-validator`, JS API
// `validateBytes`). Usage: node tests/gltf_validate.mjs FILE...
// Prints one summary line per file (errors, warnings) and every message of severity error; exits
// 1 if any file has an error or cannot be read, 2 if the validator package is not installed.
// External resources (a .gltf's .bin) are read relative to the file being validated.
import { readFile } from "node:fs/promises";
import path from "node:path";

let validator;
try {
  validator = await import("gltf-validator");
  validator = validator.default ?? validator;
} catch (e) {
  console.error("gltf-validator is not installed: run `npm ci` in the repository root");
  process.exit(2);
}

const files = process.argv.slice(2);
if (files.length === 0) {
  console.error("usage: node tests/gltf_validate.mjs FILE...");
  process.exit(2);
}

let failed = false;
for (const file of files) {
  try {
    const bytes = new Uint8Array(await readFile(file));
    const report = await validator.validateBytes(bytes, {
      uri: path.basename(file),
      maxIssues: 0,
      externalResourceFunction: (uri) =>
        readFile(path.join(path.dirname(file), decodeURIComponent(uri))).then(
          (data) => new Uint8Array(data),
        ),
    });
    const issues = report.issues;
    console.log(`${file}: ${issues.numErrors} errors, ${issues.numWarnings} warnings, ${issues.numInfos} infos`);
    for (const m of issues.messages) {
      if (m.severity === 0) {
        console.log(`  error ${m.code} at ${m.pointer ?? "?"}: ${m.message}`);
      } else if (m.severity === 1) {
        console.log(`  warning ${m.code} at ${m.pointer ?? "?"}: ${m.message}`);
      }
    }
    if (issues.numErrors > 0) failed = true;
  } catch (e) {
    console.log(`${file}: validation failed: ${e}`);
    failed = true;
  }
}
process.exit(failed ? 1 : 0);
