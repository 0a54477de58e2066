// gltf-validator (Khronos, npm) on every GLB the assets hold: 0 errors each. The extension
// itself is unknown to the validator and reported as information, not as an error.
//   node validator.test.js --assets DIR
import { readFileSync } from 'node:fs';
import validator from 'gltf-validator';
import { readAssets } from './assets.js';

const arg = (k, d) => { const i = process.argv.indexOf(k); return i > 0 ? process.argv[i + 1] : d; };
const assets = readAssets(arg('--assets'));
const files = [assets.env, ...Object.values(assets.objects).map((o) => o.glb),
               ...Object.values(assets.roundTrips || {}).map((o) => o.glb)];
let failed = false;
for (const file of files) {
  const report = await validator.validateBytes(new Uint8Array(readFileSync(file)), { maxIssues: 100 });
  const i = report.issues;
  const ok = i.numErrors === 0;
  failed ||= !ok;
  console.log(`${ok ? 'ok  ' : 'FAIL'} ${file}: ${i.numErrors} errors, ${i.numWarnings} warnings, ${i.numInfos} infos, ${i.numHints} hints`);
  for (const m of i.messages.filter((m) => m.severity <= 1)) console.log(`     ${m.severity === 0 ? 'error' : 'warning'} ${m.code}: ${m.message} (${m.pointer ?? ''})`);
}
process.exit(failed ? 1 : 0);
