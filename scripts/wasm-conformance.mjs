// Runs every course scene of the reference (SCREENSAVER_REFERENCE, default
// ../shared/reference) in the WebAssembly build under Node, with the
// default detector and, for scenes of up to 900 lines, the all-pairs
// one, and compares the counters after every step and every checkpoint
// state, byte for byte, with the reference's. One line a scene and
// detector, then `N passed, M failed`; exits 1 on any difference.
//
//   node scripts/wasm-conformance.mjs WASM_FILE
import { readFileSync, readdirSync, existsSync } from "node:fs";
import { join, dirname, resolve } from "node:path";
import { fileURLToPath } from "node:url";

const here = dirname(fileURLToPath(import.meta.url));
const reference = resolve(process.env.SCREENSAVER_REFERENCE ?? join(here, "..", "..", "shared", "reference"));
const wasmFile = process.argv[2];
if (!wasmFile) {
  console.error("usage: node scripts/wasm-conformance.mjs WASM_FILE");
  process.exit(2);
}
if (!existsSync(join(reference, "inputs"))) {
  console.error(`no reference data at ${reference} (set SCREENSAVER_REFERENCE)`);
  process.exit(2);
}
const { instance } = await WebAssembly.instantiate(readFileSync(wasmFile), {});
const ss = instance.exports;
const encoder = new TextEncoder();
const decoder = new TextDecoder();

function put(bytes) {
  const at = ss.ss_alloc(bytes.length);
  new Uint8Array(ss.memory.buffer, at, bytes.length).set(bytes);
  return at;
}
function text() {
  return decoder.decode(new Uint8Array(ss.memory.buffer, ss.ss_text_ptr(), ss.ss_text_len()));
}
function load(bytes, name, detector) {
  const nameBytes = encoder.encode(name);
  const [t, n] = [put(bytes), put(nameBytes)];
  const status = ss.ss_load(t, bytes.length, n, nameBytes.length, detector);
  ss.ss_free(t, bytes.length);
  ss.ss_free(n, nameBytes.length);
  if (status !== 0) throw new Error(text());
}

// The detectors checked, with the numbers the module gives them.
ss.ss_detectors();
const numbered = text().split(",");
const DETECTORS = ["sweep", "brute"].map((name) => [name, numbered.indexOf(name)]);
if (DETECTORS.some(([, code]) => code < 0)) throw new Error(`the module's detectors: ${numbered}`);
const BRUTE_MOST_LINES = 900;
let passed = 0;
let failed = 0;
const scenes = readdirSync(join(reference, "inputs")).filter((f) => f.endsWith(".in")).sort();
for (const file of scenes) {
  const name = file.slice(0, -3);
  const input = readFileSync(join(reference, "inputs", file));
  const counts = readFileSync(join(reference, "expected", `${name}.counts.csv`), "utf8")
    .trim().split("\n").slice(1).map((row) => row.split(",").map(Number));
  const checkpoints = readdirSync(join(reference, "expected"))
    .map((f) => f.match(new RegExp(`^${name}\\.(\\d+)\\.state$`)))
    .filter(Boolean).map((m) => Number(m[1]));
  const lines = Number(input.toString("utf8").trim().split("\n")[0]);
  for (const [detector, code] of DETECTORS) {
    if (detector === "brute" && lines > BRUTE_MOST_LINES) continue;
    const started = Date.now();
    load(input, `${name}.in`, code);
    let problem = null;
    for (const [step, wall, line] of counts) {
      ss.ss_step(1);
      if (ss.ss_steps() !== step || ss.ss_wall() !== wall || ss.ss_line() !== line) {
        problem = `step ${step}: counters ${ss.ss_wall()}/${ss.ss_line()}, reference ${wall}/${line}`;
        break;
      }
      if (checkpoints.includes(step)) {
        ss.ss_state();
        const expected = readFileSync(join(reference, "expected", `${name}.${step}.state`), "utf8");
        if (text() !== expected) {
          problem = `step ${step}: the state differs from the reference's`;
          break;
        }
      }
    }
    const seconds = ((Date.now() - started) / 1000).toFixed(1);
    const steps = counts.length;
    if (problem) {
      failed += 1;
      console.log(`FAIL ${name} (${detector}): ${problem}`);
    } else {
      passed += 1;
      console.log(`ok   ${name} (${detector}): ${steps} steps, ${checkpoints.length} states, ${seconds} s`);
    }
  }
}
console.log(`${passed} passed, ${failed} failed`);
process.exit(failed === 0 ? 0 : 1);
