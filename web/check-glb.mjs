// Validates a glb with the Khronos glTF validator (npm `gltf-validator`): exits non-zero when
// the report has any error. Usage: node check-glb.mjs FILE.glb
import fs from 'node:fs';
import validator from 'gltf-validator';

const file = process.argv[2];
const bytes = new Uint8Array(fs.readFileSync(file));
const report = await validator.validateBytes(bytes, { maxIssues: 100 });
const { numErrors, numWarnings, numInfos } = report.issues;
for (const m of report.issues.messages) {
  if (m.severity <= 1) console.log(`${m.severity === 0 ? 'error' : 'warning'} ${m.code} ${m.pointer ?? ''}: ${m.message}`);
}
console.log(`check-glb: ${file}: ${numErrors} errors, ${numWarnings} warnings, ${numInfos} infos`);
process.exit(numErrors === 0 ? 0 : 1);
