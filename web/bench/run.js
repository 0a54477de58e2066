// Drives web/bench/index.html in one headless Chromium (Debian's, through playwright-core from
// the web package's node_modules; WebGL 2 on SwiftShader): per object, view and method the frame
// times and the tone-mapped frame as a PNG. Called by scripts/bench-web:
//   node web/bench/run.js PLAN.json RESULT.json
// PLAN: { web: the web package folder, files: folder served as /files/, out: PNG folder,
//         size: [w, h], views: [[az, el, dist]...], methods: [{name, kind, ...}...],
//         objects: [{name, glb, env}...] (glb, env: paths under /files/),
//         timing: {warmup: frames per method and view first, rounds: timed rounds} }
// Timing is interleaved: each round draws one frame of every method in turn, so that a change of
// the machine's load during the run (other jobs share its cores) falls on all methods alike. Per
// frame: the page's wall time (performance.now around render + a 1-texel readPixels, which waits
// for the frame) and the CPU time the browser's processes spent meanwhile (/proc, all threads:
// SwiftShader draws on the CPU, in the GPU process).
import { readFileSync, readdirSync, writeFileSync, mkdirSync } from 'node:fs';
import { execFileSync } from 'node:child_process';
import { createRequire } from 'node:module';
import { dirname, join, resolve } from 'node:path';
import { fileURLToPath, pathToFileURL } from 'node:url';

const [planPath, resultPath] = process.argv.slice(2);
const plan = JSON.parse(readFileSync(planPath, 'utf8'));
const web = resolve(plan.web);
const require = createRequire(join(web, 'package.json'));
const { chromium } = require('playwright-core');
const { PNG } = require('pngjs');
const { startServer } = await import(pathToFileURL(join(web, 'example', 'serve.js')).href);

const TICK_MS = 1000 / Number(execFileSync('getconf', ['CLK_TCK']).toString().trim());

// CPU ms (user + system, all threads) of this process's descendants: the browser's processes.
function browserCpuMs() {
  const parent = new Map(), ticks = new Map();
  for (const entry of readdirSync('/proc')) {
    if (!/^[0-9]+$/.test(entry)) continue;
    let stat;
    try { stat = readFileSync(`/proc/${entry}/stat`, 'utf8'); } catch { continue; }
    const f = stat.slice(stat.lastIndexOf(')') + 2).split(' ');  // fields from 3 (state) on
    parent.set(Number(entry), Number(f[1]));
    ticks.set(Number(entry), Number(f[11]) + Number(f[12]));  // utime, stime
  }
  let sum = 0;
  for (const [pid, t] of ticks) {
    for (let p = parent.get(pid); p !== undefined && p > 1; p = parent.get(p))
      if (p === process.pid) { sum += t; break; }
  }
  return sum * TICK_MS;
}

function median(values) {
  const v = [...values].sort((a, b) => a - b), m = v.length >> 1;
  return v.length % 2 ? v[m] : (v[m - 1] + v[m]) / 2;
}

const here = dirname(fileURLToPath(import.meta.url));
const server = await startServer({ roots: { '/bench/': here, '/files/': resolve(plan.files) } });
const base = `http://127.0.0.1:${server.address().port}`;
// Debian's chromium, headless, WebGL 2 through ANGLE on SwiftShader (Vulkan on the CPU): the
// flags that give a WebGL 2 context without a GPU (the web package's browser tests use the same).
const browser = await chromium.launch({
  executablePath: process.env.SHREFRACT_CHROMIUM || '/usr/bin/chromium',
  args: ['--no-sandbox', '--headless=new', '--use-gl=angle', '--use-angle=swiftshader',
         '--enable-unsafe-swiftshader', '--ignore-gpu-blocklist'],
});
const result = { browser: browser.version(), size: plan.size, views: plan.views, objects: {},
                 loadAverage: { start: readFileSync('/proc/loadavg', 'utf8').trim() } };
mkdirSync(plan.out, { recursive: true });
const [w, h] = plan.size;
try {
  for (const object of plan.objects) {
    const context = await browser.newContext({ viewport: { width: w, height: h }, deviceScaleFactor: 1 });
    const page = await context.newPage();
    const problems = [];
    page.on('pageerror', (e) => problems.push(`pageerror: ${e.message}`));
    page.on('console', (m) => { if (m.type() === 'error' || m.type() === 'warning') problems.push(`console.${m.type()}: ${m.text()}`); });
    await page.goto(`${base}/bench/index.html`);
    await page.waitForFunction(() => window.benchReady === true, null, { timeout: 60000 });
    const t0 = Date.now();
    const info = await page.evaluate((a) => window.bench.load(a),
                                     { glb: `/files/${object.glb}`, env: object.env ? `/files/${object.env}` : null, size: plan.size });
    info.loadMs = Date.now() - t0;
    console.log(`${object.name}: ${info.vertices} vertices, ${info.gpu}; thickness ${info.thickness.toFixed(3)}`);
    const rows = Object.fromEntries(plan.methods.map((m) => [m.name, { method: m, views: [] }]));
    const { warmup = 2, rounds = 7 } = plan.timing;
    for (const [vi, [az, el, dist]] of plan.views.entries()) {
      await page.evaluate(([a, e, d]) => window.bench.view(a, e, d), [az, el, dist]);
      const c0 = Date.now();
      const timed = Object.fromEntries(plan.methods.map((m) => [m.name, { ms: [], cpuMs: [] }]));
      for (let round = -warmup; round < rounds; ++round) {
        for (const method of plan.methods) {
          await page.evaluate((m) => window.bench.use(m), method);
          const cpu0 = browserCpuMs();
          const [ms] = await page.evaluate(() => window.bench.time(1));
          const cpu = browserCpuMs() - cpu0;
          if (round < 0) continue;  // warm-up: programs compiled, textures uploaded, caches filled
          timed[method.name].ms.push(ms);
          timed[method.name].cpuMs.push(cpu);
        }
      }
      for (const method of plan.methods) {
        await page.evaluate((m) => window.bench.use(m), method);
        const pixels = Buffer.from(await page.evaluate(() => window.bench.capture()), 'base64');
        const png = new PNG({ width: w, height: h, colorType: 2, inputColorType: 2, inputHasAlpha: false });
        png.data = pixels;
        const file = join(plan.out, `${object.name}_v${vi}_${method.name}.png`);
        writeFileSync(file, PNG.sync.write(png, { colorType: 2, inputColorType: 2, inputHasAlpha: false }));
        rows[method.name].views.push({ view: [az, el, dist], ...timed[method.name], png: file });
      }
      console.log(`  view ${vi}: ${((Date.now() - c0) / 1000).toFixed(0)} s`);
    }
    for (const row of Object.values(rows)) {
      row.medianMs = median(row.views.flatMap((v) => v.ms));
      row.medianCpuMs = median(row.views.flatMap((v) => v.cpuMs));
      console.log(`  ${row.method.name}: median ${row.medianMs.toFixed(1)} ms, CPU ${row.medianCpuMs.toFixed(0)} ms`);
    }
    result.objects[object.name] = { info, rows, problems };
    if (problems.length) console.log(`  page problems: ${problems.slice(0, 5).join(' | ')}`);
    await context.close();
  }
  result.loadAverage.end = readFileSync('/proc/loadavg', 'utf8').trim();
} finally {
  await browser.close();
  server.close();
}
writeFileSync(resultPath, JSON.stringify(result, null, 1) + '\n');
