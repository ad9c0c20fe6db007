// The screensaver in a web page: the project's simulation, built for
// WebAssembly (wasm/lib.rs), stepped in a worker (worker.js) while this
// thread draws the state before. Scenes: the built-in one, generated ones,
// a `.in` file (picked, dropped, or given by URL). URL parameters: lines,
// kind, seed, frames, speed, hud, cycle, scene, detector; see the README's
// "In a web browser".

import { instantiate, put, text } from "./module.js";

const SMOOTH_UP_TO = 5000; // larger scenes are drawn by the project's rasteriser
const RED = "rgb(170, 20, 20)";
const GRAY = "rgb(150, 150, 150)";
const MAX_LINES = 1_000_000;
const MAX_CYCLE = 86400; // seconds, a day, as the command line
const STEP_BUDGET_MS = 14; // time for steps in one picture at `max` speed
const DEATH_CHECK_MS = 500;
const MAX_RATE = 2 ** 20; // faster than this is `max`
// The URL's spellings of hud: on (`?hud` alone too), off.
const HUD_ON = ["1", "true", "yes", "on", ""];
const HUD_OFF = ["0", "false", "no", "off"];

const $ = (id) => document.getElementById(id);
const canvas = $("picture");
const ctx = canvas.getContext("2d", { alpha: false });

let ss; // this thread's instance of the module: kind names, drawing
let kinds; // the generated scenes' kinds, in the module's order
let detectors; // the detectors' names, in the module's numbering
const worker = new Worker(new URL("worker.js", import.meta.url), { type: "module" });
const state = {
  // { type: "built-in" } | { type: "generated", kind, kindGiven, lines, seed }
  // | { type: "file", name, bytes, url } (url: where it was fetched from; none for a file from disk)
  scene: null,
  world: 0, // counts the worlds started, so that answers about an old one are dropped
  starting: false,
  busy: false, // a request for steps is with the worker
  latest: null, // the worker's last answer: steps, wall, line, points
  drawn: null, // [answer, width, height] last drawn
  detector: "sweep",
  frames: null, // frames asked for, or null: endless
  seconds: 0, // simulation time of this run
  ended: false,
  paused: false,
  pace: { kind: "frame" }, // | { kind: "rate", rate } | { kind: "max" }
  owed: 0, // steps owed at a set rate
  hud: false,
  cycle: 0, // seconds each generated scene shows, 0: no cycle
  firstGenerated: null,
  sceneIndex: 0, // the k-th scene of a cycle
  sceneStarted: 0,
  lastDeathCheck: 0,
  stepTimes: [], // [time, steps so far] of recent answers while running, for the rate
  lastRate: 0, // the rate last measured running, kept through a pause
  frameTimes: [],
  lastFrame: 0,
};

// ---- the WebAssembly module and the worker ------------------------------

let requests = 0;
const waiting = new Map();
worker.onmessage = ({ data }) => {
  waiting.get(data.id)(data);
  waiting.delete(data.id);
};
worker.onerror = (e) => showError(`the simulation stopped: ${e.message}`);

function ask(request) {
  const id = ++requests;
  worker.postMessage({ ...request, id });
  return new Promise((answer) => waiting.set(id, answer));
}

// Starts a world from a scene and, once it runs, applies `settings` (the
// state that goes with the scene: cycle, firstGenerated, sceneIndex), so
// that the form and the link describe the world on show. On failure shows
// the error, keeps the world there was, and gives the error's text (null
// when the world started). A start does not clear an error on show: the
// one who asked for it does, so that a cycle's next scene leaves a bad URL
// parameter's message in place.
async function startWorld(scene, settings = {}) {
  state.starting = true;
  const forWorker = scene.type === "generated" ? { ...scene, kindIndex: kinds.indexOf(scene.kind) } : scene;
  const detector = detectors.indexOf(state.detector);
  const answer = await ask({ type: "start", scene: forWorker, detector });
  state.starting = false;
  if (answer.error !== undefined) {
    showError(answer.error);
    return answer.error;
  }
  state.world += 1;
  Object.assign(state, settings);
  Object.assign(state, { scene, lines: answer.lines, seconds: 0, ended: false, owed: 0, latest: null, busy: false });
  state.sceneStarted = performance.now();
  state.stepTimes = [];
  state.lastRate = 0;
  $("results").hidden = true;
  syncForm();
  syncLink();
  requestSteps(0, true); // the first picture: the world as it starts
  return null;
}

// ---- running -------------------------------------------------------------

function stepsLeft() {
  if (state.ended) return 0;
  if (state.frames === null) return Infinity;
  const done = state.latest?.steps ?? 0;
  return Math.max(0, state.frames + 1 - done); // N frames are N + 1 steps
}

// Asks the worker for `steps` steps (null: as many as fit in the budget),
// at most as many as the run has left, and the state they lead to (with
// `always`, even for no step).
function requestSteps(steps, always = false) {
  const left = stepsLeft();
  if (state.busy || state.starting || (!always && (left === 0 || steps === 0))) return;
  const world = state.world;
  const now = performance.now();
  const checkDeath = now - state.lastDeathCheck >= DEATH_CHECK_MS;
  if (checkDeath) state.lastDeathCheck = now;
  const [width, height] = fitCanvas();
  state.busy = true;
  ask({
    type: "run",
    steps: steps === null ? null : Math.min(steps, left),
    budgetMs: STEP_BUDGET_MS,
    most: Number.isFinite(left) ? left : 1e9,
    width,
    height,
    checkDeath,
  }).then((answer) => {
    if (world !== state.world) return; // about a world since replaced
    state.busy = false;
    state.seconds += answer.seconds;
    answer.width = width;
    answer.height = height;
    state.latest = answer;
    // Single steps while paused say nothing of the running rate, which
    // `+` and `-` change.
    if (!state.paused) recent(state.stepTimes, performance.now(), [performance.now(), answer.steps]);
    if (stepsLeft() === 0) endRun();
    if (answer.died) state.died = true;
  });
}

// Steps for the next picture, at the pace set.
function stepsThisFrame(dtMs) {
  const pace = state.pace;
  if (pace.kind === "frame") return 1;
  if (pace.kind === "max") return null;
  state.owed = Math.min(state.owed + (pace.rate * dtMs) / 1000, pace.rate / 4 + 1);
  const n = Math.floor(state.owed);
  state.owed -= n;
  return n;
}

async function endRun() {
  if (state.ended) return;
  state.ended = true;
  const world = state.world;
  while (state.busy) await new Promise((ok) => setTimeout(ok, 5));
  if (world !== state.world) return;
  const answer = await ask({ type: "report", frames: state.frames ?? -1, seconds: state.seconds });
  const results = $("results");
  results.textContent = answer.text;
  results.hidden = false;
}

function measuredRate() {
  const t = state.stepTimes;
  if (t.length < 2) return state.lastRate;
  const [t0, s0] = t[0];
  const [t1, s1] = t[t.length - 1];
  if (t1 > t0) state.lastRate = ((s1 - s0) * 1000) / (t1 - t0);
  return state.lastRate;
}

function changePace(faster) {
  const pace = state.pace;
  let rate;
  if (pace.kind === "rate") rate = pace.rate;
  else if (pace.kind === "max" && faster) return;
  else rate = Math.max(1, measuredRate());
  rate = faster ? rate * 2 : rate / 2;
  state.pace = rate >= MAX_RATE ? { kind: "max" } : { kind: "rate", rate: Math.max(1, Math.floor(rate)) };
  state.owed = 0;
  syncLink();
}

function paceText() {
  const pace = state.pace;
  if (pace.kind === "frame") return "1 step/frame";
  if (pace.kind === "rate") return `${pace.rate} steps/s max`;
  return "max speed";
}

// The k-th scene of a cycle: the kind asked for, or each in turn; the
// seed counts on from the first.
function cycleScene(k) {
  const first = state.firstGenerated;
  const kind = first.kindGiven ? first.kind : kinds[k % kinds.length];
  return { ...first, kind, seed: first.seed + BigInt(k) };
}

function maybeNextScene(now) {
  if (!state.cycle || !state.firstGenerated || state.frames !== null || state.ended || state.starting) return;
  if (state.died || now - state.sceneStarted >= state.cycle * 1000) {
    state.died = false;
    state.sceneIndex += 1;
    startWorld(cycleScene(state.sceneIndex));
  }
}

// ---- drawing -------------------------------------------------------------

function fitCanvas() {
  const ratio = Math.min(window.devicePixelRatio || 1, 2);
  const [w, h] = [Math.round(canvas.clientWidth * ratio), Math.round(canvas.clientHeight * ratio)];
  if (canvas.width !== w || canvas.height !== h) [canvas.width, canvas.height] = [w, h];
  return [w, h];
}

// Draws the worker's last answer, if it is news or the canvas changed size
// (then the lines, mapped to the old size, are scaled to the new).
function draw() {
  const [w, h] = fitCanvas();
  const answer = state.latest;
  if (w === 0 || h === 0 || !answer) return false;
  const [drawn, dw, dh] = state.drawn ?? [];
  if (drawn === answer && dw === w && dh === h) return false;
  state.drawn = [answer, w, h];
  const points = answer.points;
  const [sx, sy] = [w / answer.width, h / answer.height];
  if (sx !== 1 || sy !== 1) {
    for (let i = 0; i < points.length; i += 5) {
      [points[i], points[i + 1], points[i + 2], points[i + 3]] =
        [points[i] * sx, points[i + 1] * sy, points[i + 2] * sx, points[i + 3] * sy];
    }
    [answer.width, answer.height] = [w, h];
  }
  if (points.length / 5 > SMOOTH_UP_TO) {
    const at = put(ss, new Uint8Array(points.buffer, points.byteOffset, points.byteLength));
    const pixels = ss.ss_draw(at, points.length, w, h);
    ss.ss_free(at, points.byteLength);
    ctx.putImageData(new ImageData(new Uint8ClampedArray(ss.memory.buffer, pixels, w * h * 4), w, h), 0, 0);
    return true;
  }
  // Small scenes: the browser's anti-aliased strokes, as wide as the
  // window's (1.5 pixels at 1180 x 800).
  ctx.fillStyle = "#000";
  ctx.fillRect(0, 0, w, h);
  ctx.lineWidth = Math.max(1, 1.5 * Math.min(w / 1180, h / 800));
  ctx.lineCap = "round";
  for (const [gray, colour] of [[0, RED], [1, GRAY]]) {
    ctx.beginPath();
    for (let i = 0; i < points.length; i += 5) {
      if (points[i + 4] !== gray) continue;
      ctx.moveTo(points[i], points[i + 1]);
      ctx.lineTo(points[i + 2], points[i + 3]);
    }
    ctx.strokeStyle = colour;
    ctx.stroke();
  }
  return true;
}

function recent(list, now, entry) {
  list.push(entry);
  while (list.length > 2 && now - list[0][0] > 1000) list.shift();
}

function showHud(now, drew) {
  const latest = state.latest;
  if (!latest) return;
  if (drew) recent(state.frameTimes, now, [now, 0]);
  // For tests and benchmarks: the step on show and the pictures drawn.
  document.body.dataset.step = latest.steps;
  if (drew) document.body.dataset.frames = (Number(document.body.dataset.frames) || 0) + 1;
  document.body.dataset.firstPicture ??= now.toFixed(0);
  if (!state.hud) return;
  const ft = state.frameTimes;
  const fps = ft.length > 1 ? ((ft.length - 1) * 1000) / (ft[ft.length - 1][0] - ft[0][0]) : 0;
  const lines = [
    `step ${latest.steps}`,
    `${latest.wall} line-wall`,
    `${latest.line} line-line`,
    `${measuredRate().toFixed(0)} steps/s  ${fps.toFixed(0)} fps`,
    `pace: ${paceText()}`,
  ];
  if (state.sceneIndex > 0) lines.push(`scene ${state.sceneIndex + 1}`);
  $("hud").textContent = lines.join("\n");
}

function frame(now) {
  const dt = state.lastFrame ? now - state.lastFrame : 16.7;
  state.lastFrame = now;
  try {
    // The next steps first: the worker steps them while this thread draws.
    if (!state.paused) requestSteps(stepsThisFrame(dt));
    const drew = draw();
    maybeNextScene(now);
    showHud(now, drew);
  } catch (e) {
    showError(`the page stopped: ${e.message}`);
    return;
  }
  requestAnimationFrame(frame);
}

// ---- controls ------------------------------------------------------------

function showError(message) {
  const box = $("error");
  box.textContent = message ?? "";
  box.hidden = message === null;
}

function act(action) {
  switch (action) {
    case "pause":
      state.paused = !state.paused;
      // The rate is measured afresh from the resume, the pause left out.
      if (!state.paused) state.stepTimes = [];
      $("controls").querySelector("[data-action=pause]").textContent = state.paused ? "Resume" : "Pause";
      break;
    case "step":
      if (state.paused) requestSteps(1);
      break;
    case "faster":
    case "slower":
      changePace(action === "faster");
      break;
    case "hud":
      state.hud = !state.hud;
      $("hud").hidden = !state.hud;
      syncLink();
      break;
    case "fullscreen":
      if (document.fullscreenElement) document.exitFullscreen();
      else document.documentElement.requestFullscreen?.().catch((e) => showError(`full screen refused: ${e.message}`));
      break;
    case "stop":
      endRun();
      break;
    case "run":
      runFromForm();
      break;
  }
}

const KEYS = { " ": "pause", ArrowRight: "step", "+": "faster", "=": "faster", "-": "slower", _: "slower",
  h: "hud", H: "hud", f: "fullscreen", F: "fullscreen", q: "stop", Q: "stop" };

function onKey(event) {
  if (event.target instanceof HTMLInputElement || event.target instanceof HTMLSelectElement) return;
  const action = KEYS[event.key];
  if (!action || event.ctrlKey || event.metaKey || event.altKey) return;
  event.preventDefault();
  act(action);
}

// A form field's value as a number from lo to hi, or null after adding
// to `problems` why it is not one (as for the URL's parameters).
function fromField(id, lo, hi, problems, whole = true) {
  const input = $(id);
  // A number field gives "" for text that is no number.
  const shown = input.validity.badInput ? "(not a number)" : input.value === "" ? "(empty)" : input.value;
  return numberIn(`${id} ${shown}`, input.value, lo, hi, problems, whole);
}

// Runs what the form asks for, or, when a field is out of its range, says
// which and why and leaves the run on show alone.
async function runFromForm() {
  const kind = $("kind").value;
  const problems = [];
  let scene;
  let cycle = 0; // a cycle shows generated scenes; the built-in scene and a file run alone
  if (kind === "built-in" || kind === "file") {
    // The built-in scene, or the file on show run again from its start.
    scene = kind === "file" && state.scene.type === "file" ? state.scene : { type: "built-in" };
  } else {
    const lines = fromField("lines", 1, MAX_LINES, problems);
    const seedText = $("seed").value;
    const seed = parseSeed(seedText);
    if (seed === null) problems.push(`seed ${seedText === "" ? "(empty)" : seedText}: expected a whole number below 2^64`);
    cycle = fromField("cycle", 0, MAX_CYCLE, problems, false);
    scene = { type: "generated", kind, kindGiven: true, lines, seed };
  }
  if (problems.length) {
    showError(problems.join("\n"));
    return;
  }
  const generated = scene.type === "generated" ? scene : null;
  if ((await startWorld(scene, { cycle, firstGenerated: generated, sceneIndex: 0 })) === null) showError(null);
}

async function openFile(file) {
  const bytes = new Uint8Array(await file.arrayBuffer());
  const settings = { cycle: 0, firstGenerated: null, sceneIndex: 0 };
  if ((await startWorld({ type: "file", name: file.name, bytes }, settings)) === null) showError(null);
}

function syncForm() {
  const scene = state.scene;
  // A file on show is a choice of its own, named by the file.
  let fileChoice = $("kind").querySelector("option[value=file]");
  if (!fileChoice) fileChoice = $("kind").appendChild(new Option("", "file"));
  fileChoice.hidden = scene.type !== "file";
  fileChoice.textContent = scene.type === "file" ? scene.name : "";
  $("kind").value = scene.type === "generated" ? scene.kind : scene.type;
  if (scene.type === "generated") {
    $("lines").value = scene.lines;
    $("seed").value = scene.seed.toString();
  }
  $("cycle").value = state.cycle;
  syncFields();
}

// Lines, seed and cycle are a generated scene's: with the built-in scene
// or a file chosen, which they do not change, they are disabled, and their
// labels' titles say why.
function syncFields() {
  const kind = $("kind").value;
  const off = kind === "built-in" || kind === "file";
  const why = kind === "built-in"
    ? "the built-in scene is always the same (1000 lines, seed 6172)"
    : "a file's scene is its own";
  for (const id of ["lines", "seed", "cycle"]) {
    const input = $(id);
    const label = input.closest("label");
    label.dataset.title ??= label.title;
    input.disabled = off;
    label.style.opacity = off ? "0.5" : "";
    label.title = off ? `For generated scenes only: ${why}; choose a kind (${kinds.join(", ")}) to set ${id}`
      : label.dataset.title;
  }
}

// The link that reproduces what is on show, or, for a file from disk,
// which no URL can name, a plain word that there is none.
function syncLink() {
  const link = $("link");
  const scene = state.firstGenerated ?? state.scene;
  if (scene?.type === "file" && scene.url === undefined) {
    link.removeAttribute("href");
    link.textContent = "no link: a file from disk";
    link.title = "A file opened from disk cannot be linked: serve it and give its URL as ?scene=URL";
    return;
  }
  link.textContent = "link";
  link.title = "A link that reproduces this run";
  const p = new URLSearchParams();
  if (scene?.type === "generated") {
    p.set("lines", scene.lines);
    if (scene.kindGiven) p.set("kind", scene.kind);
    p.set("seed", scene.seed.toString());
  } else if (scene?.type === "file") {
    p.set("scene", scene.url);
  }
  if (state.frames !== null) p.set("frames", state.frames);
  if (state.pace.kind !== "frame") p.set("speed", state.pace.kind === "max" ? "max" : state.pace.rate);
  if (state.hud) p.set("hud", "1");
  if (state.cycle && state.firstGenerated) p.set("cycle", state.cycle); // only generated scenes cycle
  if (state.detector !== "sweep") p.set("detector", state.detector);
  const query = p.toString();
  link.href = query ? `?${query}` : location.pathname;
}

// `value` as a number from lo to hi (a whole one unless `whole` is false),
// or null after adding to `problems` a line that names it by `label`.
function numberIn(label, value, lo, hi, problems, whole = true) {
  const n = Number(value);
  if (!(whole ? /^\d+$/ : /^\d+(\.\d+)?$/).test(value.trim()) || n < lo || n > hi) {
    problems.push(`${label}: expected a ${whole ? "whole " : ""}number from ${lo} to ${hi}`);
    return null;
  }
  return n;
}

function parseSeed(s) {
  if (s === null || !/^\d+$/.test(s.trim())) return null;
  const seed = BigInt(s.trim());
  return seed < 2n ** 64n ? seed : null;
}

// ---- the URL -------------------------------------------------------------

// Reads the URL's parameters into the state; gives the scene to start
// with, or an error text.
async function fromUrl() {
  const p = new URLSearchParams(location.search);
  const problems = [];
  const number = (name, lo, hi, whole = true) => {
    const v = p.get(name);
    return v === null ? null : numberIn(`${name}=${v}`, v, lo, hi, problems, whole);
  };
  state.frames = number("frames", 0, Number.MAX_SAFE_INTEGER - 1);
  const speed = p.get("speed");
  if (speed === "max") state.pace = { kind: "max" };
  else if (speed === "frame" || speed === null) state.pace = { kind: "frame" };
  else {
    // As the command line words it, with the page's most.
    const rate = numberIn(`speed=${speed}`, speed, 1, MAX_RATE, []);
    if (rate !== null) state.pace = { kind: "rate", rate };
    else problems.push(`speed=${speed}: expected steps a second (a whole number from 1 to ${MAX_RATE}), frame (one step a picture) or max`);
  }
  const hud = p.get("hud");
  if (hud === null || HUD_OFF.includes(hud.toLowerCase())) state.hud = false;
  else if (HUD_ON.includes(hud.toLowerCase())) state.hud = true;
  else problems.push(`hud=${hud}: expected 1 (or true, yes, on) to show the heads-up display, or 0 (or false, no, off)`);
  state.cycle = number("cycle", 0, MAX_CYCLE, false) ?? 0;
  const detector = p.get("detector") ?? "sweep";
  if (detectors.includes(detector)) state.detector = detector;
  else problems.push(`detector=${detector}: expected one of ${detectors.join(", ")}`);

  let kind = p.get("kind");
  if (kind !== null && !kinds.includes(kind)) {
    problems.push(`kind=${kind}: expected one of ${kinds.join(", ")}`);
    kind = null;
  }
  const lines = number("lines", 1, MAX_LINES);
  const seedText = p.get("seed");
  const seed = seedText === null ? null : parseSeed(seedText);
  if (seedText !== null && seed === null) problems.push(`seed=${seedText}: expected a whole number below 2^64`);

  const sceneUrl = p.get("scene");
  let scene = { type: "built-in" };
  let sceneRead = true;
  if (sceneUrl !== null) {
    try {
      const response = await fetch(sceneUrl);
      if (!response.ok) throw new Error(`HTTP ${response.status}`);
      scene = { type: "file", name: sceneUrl, url: sceneUrl, bytes: new Uint8Array(await response.arrayBuffer()) };
    } catch (e) {
      problems.push(`${sceneUrl}: cannot be read (${e.message})${elsewhere(sceneUrl, e)}`);
      sceneRead = false;
    }
  } else if (kind !== null || lines !== null || seed !== null || state.cycle) {
    // As the command line: a generated scene, its kind uniform (a cycle:
    // each in turn) unless given, 1000 lines, seed 6172 unless given.
    scene = { type: "generated", kind: kind ?? kinds[0], kindGiven: kind !== null, lines: lines ?? 1000,
      seed: seed ?? 6172n };
  }
  return { scene, problems, sceneRead };
}

// Why a scene's URL may fail to load where the browser says only that the
// fetch failed (a TypeError, for a request it made or refused): from
// another origin, the browser reads it only when its server allows it
// (CORS). Nothing for a scene on the page's own origin.
function elsewhere(sceneUrl, error) {
  let url;
  try {
    url = new URL(sceneUrl, location.href);
  } catch {
    return "";
  }
  if (!(error instanceof TypeError) || url.origin === location.origin) return "";
  return `: ${url.href} is on another origin than this page (${location.origin}); a scene must be on the page's `
    + "origin, or served with CORS (its server sending Access-Control-Allow-Origin)";
}

// ---- start ---------------------------------------------------------------

async function main() {
  ss = await instantiate();
  ss.ss_kinds();
  kinds = text(ss).split(",");
  ss.ss_detectors();
  detectors = text(ss).split(",");
  for (const kind of kinds) $("kind").add(new Option(kind, kind));
  const { scene, problems, sceneRead } = await fromUrl();
  const settings = { firstGenerated: scene.type === "generated" ? scene : null, sceneIndex: 0 };
  const error = await startWorld(scene, settings);
  if (error !== null) {
    // The scene the URL names does not run: its error (located, as "Open
    // .in" shows it) stays on show over the built-in scene, which the link
    // and the results name as what runs.
    problems.unshift(error);
    await startWorld({ type: "built-in" }, { firstGenerated: null });
  }
  if (error !== null || !sceneRead) problems.push("The built-in scene is on show instead.");
  if (problems.length) showError(problems.join("\n"));
  $("hud").hidden = !state.hud;

  document.addEventListener("keydown", onKey);
  $("controls").addEventListener("click", (e) => {
    const action = e.target.closest("[data-action]")?.dataset.action;
    if (action) act(action);
  });
  $("kind").addEventListener("change", syncFields);
  $("controls").addEventListener("submit", (e) => {
    e.preventDefault();
    runFromForm();
  });
  $("file").addEventListener("change", (e) => {
    const file = e.target.files[0];
    if (file) openFile(file);
    e.target.value = "";
  });
  document.addEventListener("dragover", (e) => {
    e.preventDefault();
    $("drop").hidden = false;
  });
  document.addEventListener("dragleave", (e) => {
    if (e.relatedTarget === null) $("drop").hidden = true;
  });
  document.addEventListener("drop", (e) => {
    e.preventDefault();
    $("drop").hidden = true;
    const file = e.dataTransfer?.files[0];
    if (file) openFile(file);
  });
  let idle;
  document.addEventListener("mousemove", () => {
    $("controls").classList.remove("idle");
    clearTimeout(idle);
    idle = setTimeout(() => $("controls").classList.add("idle"), 3000);
  });
  requestAnimationFrame(frame);
}

main().catch((e) => showError(`the page could not start: ${e.message}`));
