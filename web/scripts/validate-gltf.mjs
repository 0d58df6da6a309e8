// Validates glTF/GLB files with the Khronos glTF-Validator (npm
// `gltf-validator`) and prints one JSON line per file: errors, warnings and
// the error messages. Exits 1 when any file has an error. Used by the Rust
// tests of `vitrine lod` (server/tests/cli_lod.rs).
import { readFile } from 'node:fs/promises';

// gltf-validator is compiled Dart with no type declarations; a computed
// specifier keeps tsc (checkJs) from type-checking that JavaScript.
const pkg = 'gltf-validator';
/** @type {any} */
const validator = (await import(pkg)).default;

/** @typedef {{ severity: number, code: string, pointer?: string, message: string }} Issue */

let failed = false;
for (const file of process.argv.slice(2)) {
    const data = new Uint8Array(await readFile(file));
    const report = await validator.validateBytes(data, { uri: file, maxIssues: 200 });
    /** @type {Issue[]} */
    const messages = report.issues.messages;
    const errors = messages.filter((m) => m.severity === 0);
    console.log(JSON.stringify({
        file,
        errors: report.issues.numErrors,
        warnings: report.issues.numWarnings,
        messages: errors.map((m) => `${m.code} ${m.pointer ?? ''}: ${m.message}`),
        warningCodes: messages.filter((m) => m.severity === 1).map((m) => m.code),
    }));
    if (report.issues.numErrors > 0) failed = true;
}
process.exit(failed ? 1 : 0);
