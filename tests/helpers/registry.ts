// A local npm registry for the packed tarballs: it serves their packuments and tarballs, and hands
// every other request to the real registry. With npm_config_registry pointing at it, `npx gcs-skin`
// in an empty folder resolves the name as it would once published (tests/package.test.ts).
import { createHash } from 'node:crypto';
import { readFileSync } from 'node:fs';
import { createServer, type Server } from 'node:http';
import { execFileSync } from 'node:child_process';
import { basename } from 'node:path';

export interface LocalRegistry {
  url: string;
  /** The requests it answered from its own tarballs (package names), and the ones it passed on. */
  served: string[];
  proxied: string[];
  close(): Promise<void>;
}

/** The manifest (package.json) inside an npm tarball. */
function manifestOf(tarball: string): Record<string, unknown> {
  return JSON.parse(execFileSync('tar', ['-xzOf', tarball, 'package/package.json'], { encoding: 'utf8' }));
}

export function upstreamRegistry(): string {
  const npm = process.platform === 'win32' ? 'npm.cmd' : 'npm';
  return execFileSync(npm, ['config', 'get', 'registry'], { encoding: 'utf8' }).trim().replace(/\/?$/, '/');
}

export async function startRegistry(tarballs: string[], upstream = upstreamRegistry()): Promise<LocalRegistry> {
  const own = new Map<string, { packument: (url: string) => object; file: string; bytes: Buffer }>();
  for (const file of tarballs) {
    const manifest = manifestOf(file);
    const bytes = readFileSync(file);
    const name = manifest.name as string, version = manifest.version as string;
    own.set(name, {
      file: basename(file),
      bytes,
      packument: (url) => ({
        name,
        'dist-tags': { latest: version },
        versions: {
          [version]: {
            ...manifest,
            _id: `${name}@${version}`,
            dist: {
              tarball: `${url}${name}/-/${basename(file)}`,
              shasum: createHash('sha1').update(bytes).digest('hex'),
              integrity: `sha512-${createHash('sha512').update(bytes).digest('base64')}`,
            },
          },
        },
      }),
    });
  }
  const served: string[] = [], proxied: string[] = [];
  let url = '';
  const server: Server = createServer(async (req, res) => {
    const path = decodeURIComponent((req.url ?? '/').split('?')[0]).slice(1);
    for (const [name, pkg] of own) {
      if (path === name) {
        served.push(name);
        res.writeHead(200, { 'content-type': 'application/json' }).end(JSON.stringify(pkg.packument(url)));
        return;
      }
      if (path === `${name}/-/${pkg.file}`) {
        served.push(pkg.file);
        res.writeHead(200, { 'content-type': 'application/octet-stream' }).end(pkg.bytes);
        return;
      }
    }
    proxied.push(path);
    try {
      const r = await fetch(upstream + (req.url ?? '/').slice(1), { headers: { accept: req.headers.accept ?? '*/*' } });
      const body = Buffer.from(await r.arrayBuffer());
      res.writeHead(r.status, { 'content-type': r.headers.get('content-type') ?? 'application/octet-stream' }).end(body);
    } catch (e) {
      res.writeHead(502).end(String(e));
    }
  });
  await new Promise<void>((r) => server.listen(0, '127.0.0.1', r));
  const address = server.address();
  if (!address || typeof address === 'string') throw new Error('the local registry has no port');
  url = `http://127.0.0.1:${address.port}/`;
  return { url, served, proxied, close: () => new Promise<void>((r) => server.close(() => r())) };
}
