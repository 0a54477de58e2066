// A tiny static server for web/ (node's http module, nothing else): `npm run serve` prints the
// example's address; the browser tests start one on a free port. Files outside web/ are served
// only from the folders given as extra roots (URL prefix -> folder), e.g. a test's GLBs.
import { createServer } from 'node:http';
import { createReadStream, statSync } from 'node:fs';
import { dirname, extname, join, normalize, resolve, sep } from 'node:path';
import { fileURLToPath } from 'node:url';

const webRoot = resolve(dirname(fileURLToPath(import.meta.url)), '..');
const TYPES = {
  '.html': 'text/html', '.js': 'text/javascript', '.mjs': 'text/javascript', '.json': 'application/json',
  '.glb': 'model/gltf-binary', '.gltf': 'model/gltf+json', '.png': 'image/png', '.css': 'text/css',
};

export function startServer({ port = 0, roots = {} } = {}) {
  const mounts = Object.entries({ ...roots, '/': webRoot });
  const server = createServer((req, res) => {
    const path = decodeURIComponent(new URL(req.url, 'http://x').pathname);
    for (const [prefix, folder] of mounts) {
      if (!path.startsWith(prefix)) continue;
      const base = resolve(folder);
      const file = normalize(join(base, path.slice(prefix.length)));
      if (file !== base && !file.startsWith(base + sep)) break;
      let target = file;
      try {
        if (statSync(target).isDirectory()) target = join(target, 'index.html');
        statSync(target);
      } catch {
        continue;
      }
      res.writeHead(200, { 'Content-Type': TYPES[extname(target)] || 'application/octet-stream', 'Cache-Control': 'no-store' });
      createReadStream(target).pipe(res);
      return;
    }
    res.writeHead(404, { 'Content-Type': 'text/plain' });
    res.end(`not found: ${path}`);
  });
  return new Promise((done) => server.listen(port, '127.0.0.1', () => done(server)));
}

if (process.argv[1] === fileURLToPath(import.meta.url)) {
  const port = Number(process.env.PORT || 8080);
  const server = await startServer({ port, roots: { '/files/': process.env.SHREFRACT_FILES || process.cwd() } });
  const { port: p } = server.address();
  console.log(`shrefract example: http://127.0.0.1:${p}/example/?glb=/files/OBJECT.glb&env=/files/ENV.glb`);
  console.log(`(/files/ serves ${process.env.SHREFRACT_FILES || process.cwd()}; set SHREFRACT_FILES to change it)`);
}
