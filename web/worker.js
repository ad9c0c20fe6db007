// The page's simulation, off the page's thread: one world in the
// WebAssembly module, stepped on request. Each answer carries the counters
// and the lines mapped to the picture's pixels (five numbers a line, see
// wasm/lib.rs's ss_points), so that the page draws one state while the
// next is stepped.
//
// Requests: { type: "start", id, scene, detector } (the detector's number:
//           its place in DetectorKind::ALL: 0 all pairs, 1 quadtree, 2 sweep),
//           { type: "run", id, steps, budgetMs, width, height, checkDeath }
//           { type: "report", id, frames, seconds }.
// Answers carry the request's id.

import { instantiate, put, text } from "./module.js";

const encoder = new TextEncoder();
let ss;
const ready = instantiate().then((exports) => (ss = exports));

function start({ scene, detector: code }) {
  let status;
  if (scene.type === "built-in") {
    status = ss.ss_built_in(code);
  } else if (scene.type === "generated") {
    const seed = BigInt.asUintN(64, scene.seed);
    status = ss.ss_generate(scene.kindIndex, scene.lines, Number(seed & 0xffffffffn), Number(seed >> 32n), code);
  } else {
    const name = encoder.encode(scene.name);
    const [t, n] = [put(ss, scene.bytes), put(ss, name)];
    status = ss.ss_load(t, scene.bytes.length, n, name.length, code);
    ss.ss_free(t, scene.bytes.length);
    ss.ss_free(n, name.length);
  }
  return status === 0 ? { lines: ss.ss_lines() } : { error: text(ss) };
}

// Runs `steps` steps, or (steps null) as many as fit in `budgetMs` (at
// least one, at most `most`).
function run({ steps, budgetMs, most, width, height, checkDeath }) {
  const started = performance.now();
  let done = 0;
  if (steps !== null) {
    ss.ss_step(steps);
    done = steps;
  } else {
    let batch = 1;
    while (done < most) {
      const n = Math.min(batch, most - done);
      ss.ss_step(n);
      done += n;
      const spent = performance.now() - started;
      if (spent >= budgetMs) break;
      // Aim the next batch at the time left, by the pace so far.
      batch = Math.max(1, Math.floor(((budgetMs - spent) * done) / Math.max(spent, 0.01)));
    }
  }
  const seconds = (performance.now() - started) / 1000;
  const at = ss.ss_points(width, height); // may grow the memory: read the buffer after
  const points = new Float32Array(ss.memory.buffer, at, ss.ss_points_len()).slice();
  return {
    ran: done,
    seconds,
    steps: ss.ss_steps(),
    wall: ss.ss_wall(),
    line: ss.ss_line(),
    died: checkDeath ? ss.ss_died_out() === 1 : false,
    points,
  };
}

onmessage = async ({ data }) => {
  await ready;
  let answer;
  if (data.type === "start") answer = start(data);
  else if (data.type === "run") answer = run(data);
  else {
    ss.ss_report(data.frames, data.seconds);
    answer = { text: text(ss) };
  }
  answer.id = data.id;
  answer.type = data.type;
  postMessage(answer, answer.points ? [answer.points.buffer] : []);
};
