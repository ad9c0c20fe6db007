// The page in a headless browser, for scripts/web-test.mjs and
// scripts/web-bench.mjs: a server on 127.0.0.1 for the built page (and the
// reference's files under /reference/, a test's own under /scratch/),
// Debian's Chromium driven through chromedriver (WebDriver over HTTP, no
// client library).
import { spawn } from "node:child_process";
import { createServer } from "node:http";
import { readFileSync, statSync } from "node:fs";
import { join, extname } from "node:path";

const TYPES = { ".html": "text/html", ".js": "text/javascript", ".css": "text/css", ".wasm": "application/wasm" };
export const sleep = (ms) => new Promise((ok) => setTimeout(ok, ms));

// Serves `dist` at /, and `reference` and `scratch` (if given) at
// /reference/ and /scratch/; adds the path of each request it cannot
// answer to `missing`. Files only: a folder is not found (404), a path
// that does not decode (a malformed `%` escape) is a bad request (400),
// and a file it cannot read is a server error (500); the server goes on
// serving after each. Exported for scripts/web-browser-test.mjs.
export async function serve(dist, reference, scratch, missing) {
  const server = createServer((request, response) => {
    const refuse = (status, text, what) => {
      missing.push(what);
      response.writeHead(status, { "content-type": "text/plain" }).end(text);
    };
    let path;
    try {
      path = decodeURIComponent(new URL(request.url, "http://x").pathname);
    } catch {
      refuse(400, "bad request: the path does not decode", request.url);
      return;
    }
    const file = path.startsWith("/reference/") && reference
      ? join(reference, path.slice("/reference/".length))
      : path.startsWith("/scratch/") && scratch
        ? join(scratch, path.slice("/scratch/".length))
        : join(dist, path === "/" ? "index.html" : path);
    let isFile = false;
    try {
      isFile = !path.includes("..") && statSync(file).isFile();
    } catch {
      // No such file, or a name the file system refuses (a NUL): not found.
    }
    if (!isFile) {
      refuse(404, "not found", path);
      return;
    }
    let body;
    try {
      body = readFileSync(file);
    } catch (e) {
      refuse(500, `cannot read it: ${e.code ?? e.message}`, path);
      return;
    }
    response.writeHead(200, { "content-type": TYPES[extname(file)] ?? "text/plain" });
    response.end(body);
  });
  await new Promise((ok) => server.listen(0, "127.0.0.1", ok));
  return server;
}

// Starts the server and a browser of `width` x `height`; gives the calls
// the scripts use, and `missing`: the paths the server could not answer
// (404, and 400 or 500 as `serve` says).
export async function startBrowser({ dist, reference, scratch, width = 1180, height = 800 }) {
  const missing = [];
  const server = await serve(dist, reference, scratch, missing);
  const page = `http://127.0.0.1:${server.address().port}/`;
  const port = 20000 + (process.pid % 20000);
  const driver = spawn("chromedriver", [`--port=${port}`], { stdio: "ignore" });
  const base = `http://127.0.0.1:${port}`;

  async function call(method, path, body) {
    const response = await fetch(base + path, {
      method,
      headers: { "content-type": "application/json" },
      body: body === undefined ? undefined : JSON.stringify(body),
    });
    const json = await response.json();
    if (!response.ok) throw new Error(`${method} ${path}: ${json.value?.message ?? response.status}`);
    return json.value;
  }

  for (let i = 0; ; i++) {
    try {
      if ((await call("GET", "/status")).ready) break;
    } catch (e) {
      if (i > 100) throw new Error(`chromedriver did not start: ${e.message}`);
    }
    await sleep(100);
  }
  const { sessionId } = await call("POST", "/session", {
    capabilities: {
      alwaysMatch: {
        browserName: "chrome",
        "goog:chromeOptions": {
          binary: process.env.CHROMIUM ?? "/usr/bin/chromium",
          args: ["--headless=new", "--no-sandbox", "--disable-dev-shm-usage", `--window-size=${width},${height}`,
            "--hide-scrollbars"],
        },
      },
    },
  });
  const session = (path) => `/session/${sessionId}${path}`;
  const run = (script, ...args) => call("POST", session("/execute/sync"), { script, args });
  return {
    missing,
    call,
    session,
    run,
    open: (query) => call("POST", session("/url"), { url: page + query }),
    // The element's text, or null while it is hidden.
    textOf: (id) => run("const e = document.getElementById(arguments[0]); return e.hidden ? null : e.textContent;", id),
    screenshot: async () => Buffer.from(await call("GET", session("/screenshot")), "base64"),
    // Waits until `check` gives a value (not null, undefined or false).
    async until(what, check, seconds = Number(process.env.WEB_TEST_WAIT ?? 120)) {
      const end = Date.now() + seconds * 1000;
      for (;;) {
        const value = await check();
        if (value !== null && value !== undefined && value !== false) return value;
        if (Date.now() > end) {
          const seen = await run("return [document.body.dataset.step, document.getElementById('error').textContent];");
          throw new Error(`timed out waiting for ${what} (step ${seen[0]}, error: ${seen[1] || "none"})`);
        }
        await sleep(100);
      }
    },
    async close() {
      await call("DELETE", session("")).catch(() => {});
      driver.kill();
      server.close();
    },
  };
}
