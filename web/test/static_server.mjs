// A static file server for the browser tests and benchmarks, as hosts behave: `ranges: true` answers
// whole files (200) or one byte range (Range: bytes=a-b, 206) like object stores and CDNs; `ranges:
// false` is the plainest host, whole files only. Every request is logged in `requests`
// ({path, status, bytes}). Listens on 127.0.0.1 at a free port.
import fs from "node:fs";
import http from "node:http";
import path from "node:path";

const types = { ".html": "text/html", ".js": "text/javascript", ".mjs": "text/javascript", ".css": "text/css", ".json": "application/json" };

export async function serveStatic(siteDir, { ranges = true } = {}) {
  const requests = [];
  const server = http.createServer((req, res) => {
    const rel = path.normalize(decodeURIComponent(new URL(req.url, "http://x").pathname)).replace(/^(\.\.[/\\])+/, "").replace(/^\/+/, "");
    const file = path.join(siteDir, rel === "" || rel.endsWith("/") ? rel + "index.html" : rel);
    fs.stat(file, (err, st) => {
      if (err || !st.isFile()) { requests.push({ path: rel, status: 404 }); res.writeHead(404); return res.end(); }
      const type = types[path.extname(file)] || "application/octet-stream";
      const m = ranges ? /^bytes=(\d+)-(\d+)$/.exec(req.headers.range || "") : null;
      if (!m) {
        requests.push({ path: rel, status: 200, bytes: st.size });
        res.writeHead(200, { "Content-Type": type, "Content-Length": st.size, ...(ranges ? { "Accept-Ranges": "bytes" } : {}) });
        return fs.createReadStream(file).pipe(res);
      }
      const a = Number(m[1]), b = Math.min(Number(m[2]), st.size - 1);
      if (a > b) { requests.push({ path: rel, status: 416 }); res.writeHead(416); return res.end(); }
      requests.push({ path: rel, status: 206, bytes: b - a + 1 });
      res.writeHead(206, { "Content-Type": type, "Content-Length": b - a + 1, "Content-Range": `bytes ${a}-${b}/${st.size}` });
      fs.createReadStream(file, { start: a, end: b }).pipe(res);
    });
  });
  await new Promise((r) => server.listen(0, "127.0.0.1", r));
  return { url: `http://127.0.0.1:${server.address().port}/`, requests, close: () => server.close() };
}
