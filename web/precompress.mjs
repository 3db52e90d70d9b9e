// Writes a Brotli (`.br`, quality 11) and a gzip (`.gz`, level 9) copy beside every .wasm and
// .js file of a release build, so that a static host that serves precompressed files (nginx's
// gzip_static / brotli_static, Caddy's `file_server { precompressed br gzip }`, the test
// harness's server) sends the smallest one the browser accepts without compressing on the fly.
// Brotli at quality 11 takes the WebGL2 build's wasm from 1.88 MB (gzip -9) to 1.47 MB; it is
// too slow for a server to do per request (about 9 s here), hence files made once per build.
//
// Trunk runs it after each build (Trunk.toml's post_build hook) on the staging directory;
// `node web/precompress.mjs DIR` runs it on any directory. It does nothing for debug builds
// (TRUNK_PROFILE=debug) or with CLOUDSKETCH_PRECOMPRESS=0 (scripts/serve.sh: Trunk's own
// server sends the files uncompressed, so rebuilding them on every change would only cost time).
import fs from 'node:fs';
import path from 'node:path';
import zlib from 'node:zlib';
import { promisify } from 'node:util';

const brotli = promisify(zlib.brotliCompress);
const gzip = promisify(zlib.gzip);

/** The files to compress: every .wasm and .js below `dir`. */
function targets(dir) {
  return fs.readdirSync(dir, { recursive: true, withFileTypes: true })
    .filter((e) => e.isFile() && /\.(wasm|js)$/.test(e.name))
    .map((e) => path.join(e.parentPath ?? e.path, e.name));
}

async function compress(file) {
  const bytes = fs.readFileSync(file);
  const [br, gz] = await Promise.all([
    brotli(bytes, {
      params: {
        [zlib.constants.BROTLI_PARAM_QUALITY]: zlib.constants.BROTLI_MAX_QUALITY,
        [zlib.constants.BROTLI_PARAM_LGWIN]: zlib.constants.BROTLI_MAX_WINDOW_BITS,
        [zlib.constants.BROTLI_PARAM_SIZE_HINT]: bytes.length,
      },
    }),
    gzip(bytes, { level: 9 }),
  ]);
  fs.writeFileSync(`${file}.br`, br);
  fs.writeFileSync(`${file}.gz`, gz);
  return { file, raw: bytes.length, br: br.length, gz: gz.length };
}

const dir = process.argv[2] ?? process.env.TRUNK_STAGING_DIR;
if (process.env.CLOUDSKETCH_PRECOMPRESS === '0' || process.env.TRUNK_PROFILE === 'debug') {
  process.exit(0);
}
if (!dir || !fs.existsSync(dir)) {
  console.error(`precompress: no directory to compress (got ${dir ?? 'nothing'}): pass one, or run from Trunk`);
  process.exit(1);
}
const mb = (n) => `${(n / 1e6).toFixed(2)} MB`;
for (const r of await Promise.all(targets(dir).map(compress))) {
  console.log(`precompress: ${path.relative(dir, r.file)} ${mb(r.raw)} → brotli ${mb(r.br)}, gzip ${mb(r.gz)}`);
}
