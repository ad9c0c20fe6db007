// The test server of scripts/web-browser.mjs, without a browser or a
// build: it answers a folder with 404 and a path that does not decode (a
// malformed `%` escape) with 400, and goes on serving; the files it serves
// come whole. Prints one line a check and `N passed, M failed`; exits 1 on
// a failure.
//
//   node scripts/web-browser-test.mjs
import { mkdtempSync, mkdirSync, writeFileSync, rmSync } from "node:fs";
import { join } from "node:path";
import { tmpdir } from "node:os";
import { request } from "node:http";
import { serve } from "./web-browser.mjs";

const root = mkdtempSync(join(tmpdir(), "screensaver-server-"));
const [dist, reference, scratch] = ["dist", "reference", "scratch"].map((d) => join(root, d));
for (const d of [dist, join(dist, "folder"), join(reference, "inputs"), scratch]) mkdirSync(d, { recursive: true });
const page = "<!doctype html><title>page</title>";
writeFileSync(join(dist, "index.html"), page);
writeFileSync(join(dist, "screensaver.js"), "// the page's script\n");
writeFileSync(join(reference, "inputs", "tiny.in"), "0\n");

const missing = [];
const server = await serve(dist, reference, scratch, missing);
const port = server.address().port;

// GET `path` as written (no escaping by a client library): status and body.
function get(path) {
  return new Promise((ok, fail) => {
    const req = request({ host: "127.0.0.1", port, path, method: "GET" }, (response) => {
      const chunks = [];
      response.on("data", (c) => chunks.push(c));
      response.on("end", () => ok({
        status: response.statusCode,
        type: response.headers["content-type"],
        body: Buffer.concat(chunks).toString(),
      }));
    });
    req.on("error", fail);
    req.setTimeout(5000, () => req.destroy(new Error("no answer in 5 s")));
    req.end();
  });
}

let passed = 0;
let failed = 0;
async function check(name, body) {
  try {
    const detail = await body();
    passed += 1;
    console.log(`ok   ${name}${detail ? `: ${detail}` : ""}`);
  } catch (e) {
    failed += 1;
    console.log(`FAIL ${name}: ${e.message}`);
  }
}
// Asks for `path`; the answer must have `status` (and `body`, if given).
function expect(path, status, body) {
  return async () => {
    const got = await get(path);
    if (got.status !== status) throw new Error(`${path}: status ${got.status}, expected ${status}`);
    if (body !== undefined && got.body !== body) throw new Error(`${path}: body ${JSON.stringify(got.body)}`);
    return `${path} -> ${got.status}`;
  };
}

await check("/ is the page", expect("/", 200, page));
await check("a folder of the page is not found", expect("/folder", 404));
await check("a folder with its slash is not found", expect("/folder/", 404));
await check("the reference's folders are not found", expect("/reference/inputs/", 404));
await check("the scratch folder is not found", expect("/scratch/", 404));
await check("a malformed % escape is a bad request", expect("/%zz", 400));
await check("a % escape cut short is a bad request", expect("/screensaver.js%", 400));
await check("an escaped NUL is not found", expect("/%00", 404));
await check("a path out of the folders is not found", expect("/reference/../dist/index.html", 404));
await check("a missing file is not found", expect("/nothing.js", 404));
await check("the server still serves a file after all that, with its type", async () => {
  const got = await get("/screensaver.js");
  if (got.status !== 200 || got.body !== "// the page's script\n" || got.type !== "text/javascript") {
    throw new Error(JSON.stringify(got));
  }
  return `/screensaver.js -> ${got.status} ${got.type}`;
});
await check("and the reference's files, an escaped name decoded", expect("/reference/inputs/tiny%2Ein", 200, "0\n"));
await check("every request it could not answer is listed", async () => {
  const want = ["/folder", "/folder/", "/reference/inputs/", "/scratch/", "/%zz", "/screensaver.js%", "\0",
    "/nothing.js"];
  for (const w of want) {
    if (!missing.some((m) => m === w || m.endsWith(w))) throw new Error(`${JSON.stringify(w)} not in ${JSON.stringify(missing)}`);
  }
  return `${missing.length} listed`;
});

server.close();
rmSync(root, { recursive: true, force: true });
console.log(`${passed} passed, ${failed} failed`);
process.exit(failed === 0 ? 0 : 1);
