// The web page's speed in headless Chromium (a benchmark, not a test):
// pictures and steps a second at one step a picture and at `max` for
// 10^3, 10^4 and 10^5 lines, the first picture's time after load, the
// page's weight, and the WebAssembly simulation's time against the native
// binary on one thread, side by side: in the page (the results block's
// simulation time, with the page drawing beside it) and the module alone
// on the page's thread; medians of ROUNDS interleaved rounds. Prints
// Markdown tables.
//
//   node scripts/web-bench.mjs DIST_DIR NATIVE_BINARY [ROUNDS]
import { execFileSync } from "node:child_process";
import { readdirSync, statSync } from "node:fs";
import { join, dirname, resolve } from "node:path";
import { fileURLToPath } from "node:url";
import { startBrowser, sleep } from "./web-browser.mjs";

const here = dirname(fileURLToPath(import.meta.url));
const [dist, native] = process.argv.slice(2, 4).map((p) => resolve(p));
const rounds = Number(process.argv[4] ?? 3);
const reference = resolve(process.env.SCREENSAVER_REFERENCE ?? join(here, "..", "..", "shared", "reference"));
const browser = await startBrowser({ dist, reference, width: 1920, height: 1080 });
const { run, open, textOf, until } = browser;
const median = (xs) => [...xs].sort((a, b) => a - b)[Math.floor(xs.length / 2)];
const sample = () => run("return [performance.now(), Number(document.body.dataset.step), Number(document.body.dataset.frames)];");

const weight = readdirSync(dist).reduce((sum, f) => sum + statSync(join(dist, f)).size, 0);
console.log(`Page weight: ${weight.toLocaleString("en")} bytes (${readdirSync(dist).join(", ")}).\n`);

const firsts = [];
for (let r = 0; r < rounds; r++) {
  await open(`?r=${r}`);
  firsts.push(Number(await until("a picture", () => run("return document.body.dataset.firstPicture ?? null;"))));
}
console.log(`First picture of the built-in scene: ${median(firsts).toFixed(0)} ms after the page's start (median of ${rounds}).\n`);

console.log("| lines | pace | pictures/s | steps/s |");
console.log("|---:|---|---:|---:|");
for (const lines of process.env.WEB_BENCH_SKIP_DRAWING ? [] : [1000, 10000, 100000]) {
  for (const speed of ["frame", "max"]) {
    await open(`?lines=${lines}&seed=7&speed=${speed}`);
    await until("the scene running", async () => (await sample())[1] > 5);
    const [t0, s0, f0] = await sample();
    await sleep(5000);
    const [t1, s1, f1] = await sample();
    const seconds = (t1 - t0) / 1000;
    console.log(`| ${lines.toLocaleString("en")} | ${speed === "frame" ? "one step a picture" : "max"} | ${((f1 - f0) / seconds).toFixed(1)} | ${((s1 - s0) / seconds).toFixed(1)} |`);
  }
}

// The simulation alone: the results block's time in the page and in the
// native binary on one thread.
const course = (name) => ["F", join(reference, "inputs", `${name}.in`)];
const workloads = [
  ["mit", 4000, "scene=reference/inputs/mit.in", course("mit")],
  ["koch", 1000, "scene=reference/inputs/koch.in", course("koch")],
  ["sin_wave", 4000, "scene=reference/inputs/sin_wave.in", course("sin_wave")],
  ["10,000 lines", 1000, "lines=10000&seed=7", ["--lines", "10000", "--seed", "7", "F"]],
  ["100,000 lines", 100, "lines=100000&seed=7", ["--lines", "100000", "--seed", "7", "F"]],
];
const seconds = (text) => Number(text.match(/Elapsed execution time: ([\d.]+)s/)[1]);
// The module alone on the page's thread, nothing drawn: a fresh instance
// (so V8 compiles it anew, as for a visitor), the scene, then the steps.
const ALONE = `
  const [query, steps, done] = arguments;
  (async () => {
    const ss = (await WebAssembly.instantiateStreaming(fetch("screensaver.wasm"), {})).instance.exports;
    const p = new URLSearchParams(query);
    ss.ss_detectors();
    const names = new TextDecoder().decode(new Uint8Array(ss.memory.buffer, ss.ss_text_ptr(), ss.ss_text_len()));
    const sweep = names.split(",").indexOf("sweep");
    if (p.has("scene")) {
      const bytes = new Uint8Array(await (await fetch(p.get("scene"))).arrayBuffer());
      const at = ss.ss_alloc(bytes.length);
      new Uint8Array(ss.memory.buffer, at, bytes.length).set(bytes);
      ss.ss_load(at, bytes.length, at, 0, sweep);
    } else {
      ss.ss_generate(0, Number(p.get("lines")), Number(p.get("seed")), 0, sweep);
    }
    const started = performance.now();
    ss.ss_step(steps);
    done((performance.now() - started) / 1000);
  })();`;
await browser.call("POST", browser.session("/timeouts"), { script: 600000 });
console.log("\n| workload | frames | in the page (s) | WebAssembly alone (s) | native, one thread (s) | page / native | alone / native |");
console.log("|---|---:|---:|---:|---:|---:|---:|");
for (const [name, frames, query, args] of workloads) {
  const [web, alone, nat] = [[], [], []];
  for (let r = 0; r < rounds; r++) {
    await open(`?${query}&frames=${frames}&speed=max`);
    web.push(seconds(await until("the results", () => textOf("results"), 600)));
    await open("?frames=0");
    alone.push(await browser.call("POST", browser.session("/execute/async"), { script: ALONE, args: [query, frames + 1] }));
    const out = execFileSync(native, ["--threads", "1", ...args.map((a) => (a === "F" ? String(frames) : a))],
      { encoding: "utf8" });
    nat.push(seconds(out));
  }
  const [w, a, n] = [median(web), median(alone), median(nat)];
  console.log(`| ${name} | ${frames} | ${w.toFixed(3)} | ${a.toFixed(3)} | ${n.toFixed(3)} | ${(w / n).toFixed(2)}x | ${(a / n).toFixed(2)}x |`);
}
await browser.close();
