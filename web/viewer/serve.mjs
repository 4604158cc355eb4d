// serve.mjs - a static file server for the viewer (no dependencies):
//   node web/viewer/serve.mjs [--port 8080] [--mount /files=DIR ...]
// serves web/ at / (the viewer is /viewer/, three.js comes from /node_modules/), and each
// --mount prefix from its folder. Used by the browser tests too (startServer).
import { createServer } from 'node:http';
import { createReadStream, statSync } from 'node:fs';
import { extname, join, normalize, resolve, sep, dirname } from 'node:path';
import { fileURLToPath } from 'node:url';

const WEB = resolve(dirname(fileURLToPath(import.meta.url)), '..');
const TYPES = { '.html': 'text/html', '.js': 'text/javascript', '.mjs': 'text/javascript', '.css': 'text/css',
  '.json': 'application/json', '.glb': 'model/gltf-binary', '.gltf': 'model/gltf+json', '.png': 'image/png',
  '.jpg': 'image/jpeg', '.bin': 'application/octet-stream', '.wasm': 'application/wasm' };

function resolvePath(mounts, urlPath) {
  const path = decodeURIComponent(urlPath.split('?')[0]);
  for (const [prefix, folder] of mounts) {
    if (!path.startsWith(prefix)) continue;
    const file = normalize(join(folder, path.slice(prefix.length)));
    if (file !== folder && !file.startsWith(folder + sep)) return null; // no escaping the folder
    return file;
  }
  return null;
}

/** Starts the server; resolves to {server, url}. mounts: {'/prefix/': folder}. */
export function startServer({ port = 0, mounts = {} } = {}) {
  const table = Object.entries(mounts).map(([p, f]) => [p.endsWith('/') ? p : p + '/', resolve(f)]);
  table.sort((a, b) => b[0].length - a[0].length);
  table.push(['/', WEB]);
  const server = createServer((request, response) => {
    let file = resolvePath(table, request.url);
    try {
      if (file && statSync(file).isDirectory()) file = join(file, 'index.html');
      if (!file || !statSync(file).isFile()) throw new Error('not found');
    } catch {
      response.writeHead(404).end('not found');
      return;
    }
    response.writeHead(200, { 'Content-Type': TYPES[extname(file)] || 'application/octet-stream', 'Cache-Control': 'no-store' });
    createReadStream(file).pipe(response);
  });
  return new Promise((done) => server.listen(port, '127.0.0.1', () => done({ server, url: `http://127.0.0.1:${server.address().port}` })));
}

if (process.argv[1] && resolve(process.argv[1]) === fileURLToPath(import.meta.url)) {
  const args = process.argv.slice(2), mounts = {};
  let port = 8080;
  for (let i = 0; i < args.length; ++i) {
    if (args[i] === '--port') port = Number(args[++i]);
    else if (args[i] === '--mount') { const [prefix, folder] = args[++i].split('='); mounts[prefix] = folder; }
    else { console.error(`Error: unknown argument ${args[i]}`); process.exit(2); }
  }
  startServer({ port, mounts }).then(({ url }) => console.log(`Skinpack viewer: ${url}/viewer/`));
}
