// validate.mjs - runs the Khronos glTF validator (npm gltf-validator) on each file given.
// Prints one summary line a file (and every error and warning); exits 1 if any file has errors.
//   node tools/validate.mjs [--json] FILE.glb|FILE.gltf ...
import { readFile } from 'node:fs/promises';
import path from 'node:path';
import validator from 'gltf-validator';

const args = process.argv.slice(2);
const json = args.includes('--json');
const files = args.filter((a) => a !== '--json');
if (files.length === 0) {
  console.error('usage: node tools/validate.mjs [--json] FILE...');
  process.exit(2);
}

let failed = false;
for (const file of files) {
  let report;
  try {
    const bytes = new Uint8Array(await readFile(file));
    report = await validator.validateBytes(bytes, {
      uri: file,
      maxIssues: 0, // report everything
      // Relative uris of a .gltf resolve next to it; data: uris are handled by the validator.
      externalResourceFunction: (uri) =>
        readFile(path.resolve(path.dirname(file), decodeURIComponent(uri))).then((b) => new Uint8Array(b)),
    });
  } catch (error) {
    console.error(`${file}: validator failed: ${error}`);
    failed = true;
    continue;
  }
  const issues = report.issues;
  if (json) {
    console.log(JSON.stringify({ file, issues: { numErrors: issues.numErrors, numWarnings: issues.numWarnings,
      numInfos: issues.numInfos, messages: issues.messages } }));
  } else {
    console.log(`${file}: ${issues.numErrors} errors, ${issues.numWarnings} warnings, ${issues.numInfos} infos`);
    for (const m of issues.messages) {
      if (m.severity <= 1) console.log(`  ${m.severity === 0 ? 'error' : 'warning'} ${m.code} ${m.pointer ?? ''}: ${m.message}`);
    }
  }
  if (issues.numErrors > 0) failed = true;
}
process.exit(failed ? 1 : 0);
