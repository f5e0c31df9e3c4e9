// Prints the Khronos glTF-Validator's JSON report for one .glb/.gltf file.
//
//   node validate.mjs FILE.glb
//
// Exit status: 0 when a report was printed (whatever it says: the caller
// reads `issues.numErrors` / `issues.numWarnings`), 2 on bad usage or an
// unreadable file, 3 when the validator could not parse the input at all.
// Install once with `npm ci --prefix tests/gltf-validator`.
import { readFile } from "node:fs/promises";
import { basename } from "node:path";
import validator from "gltf-validator";

const file = process.argv[2];
if (!file || process.argv.length > 3) {
  console.error("usage: node validate.mjs FILE.glb");
  process.exit(2);
}

let bytes;
try {
  bytes = new Uint8Array(await readFile(file));
} catch (err) {
  console.error(`cannot read ${file}: ${err.message}`);
  process.exit(2);
}

try {
  const report = await validator.validateBytes(bytes, {
    uri: basename(file),
    maxIssues: 0, // report every issue
    writeTimestamp: false,
  });
  console.log(JSON.stringify(report, null, 2));
} catch (err) {
  console.error(`gltf-validator rejected ${file}: ${err}`);
  process.exit(3);
}
