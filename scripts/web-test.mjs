// The web page's tests, in a real browser: Debian's headless Chromium
// driven through chromedriver (WebDriver over HTTP), the page served from
// 127.0.0.1 by this script, with ../shared/reference/inputs (or
// $SCREENSAVER_REFERENCE/inputs) served beside it under /reference/.
// Prints one line a check and `N passed, M failed`; exits 1 on a failure.
// WEB_TEST_ONLY=REGEX runs only the checks whose names it matches.
//
//   node scripts/web-test.mjs DIST_DIR NATIVE_BINARY
import { execFileSync, spawnSync } from "node:child_process";
import { readFileSync, existsSync, mkdtempSync, mkdirSync, writeFileSync, rmSync } from "node:fs";
import { join, dirname, resolve } from "node:path";
import { tmpdir } from "node:os";
import { fileURLToPath } from "node:url";
import { inflateSync } from "node:zlib";
import { startBrowser, sleep } from "./web-browser.mjs";

const here = dirname(fileURLToPath(import.meta.url));
const [dist, native] = process.argv.slice(2).map((p) => resolve(p));
if (!dist || !native) {
  console.error("usage: node scripts/web-test.mjs DIST_DIR NATIVE_BINARY");
  process.exit(2);
}
const reference = resolve(process.env.SCREENSAVER_REFERENCE ?? join(here, "..", "..", "shared", "reference"));
if (!existsSync(join(reference, "inputs"))) {
  console.error(`no reference data at ${reference} (set SCREENSAVER_REFERENCE)`);
  process.exit(2);
}

// Files the tests write, served under /scratch/ (and named so from here,
// so that the native binary, run here, names them as the page does).
const scratchRoot = mkdtempSync(join(tmpdir(), "screensaver-web-"));
const scratch = join(scratchRoot, "scratch");
mkdirSync(scratch);

const browser = await startBrowser({ dist, reference, scratch });
const { call, session, run, open, textOf, until } = browser;

// ---- screenshots ---------------------------------------------------------

// Decodes a PNG of 8-bit RGB or RGBA (what the browser gives) into RGBA.
function decodePng(png) {
  let at = 8;
  let width, height, type;
  const data = [];
  while (at < png.length) {
    const length = png.readUInt32BE(at);
    const kind = png.toString("latin1", at + 4, at + 8);
    const body = png.subarray(at + 8, at + 8 + length);
    if (kind === "IHDR") [width, height, type] = [body.readUInt32BE(0), body.readUInt32BE(4), body[9]];
    if (kind === "IDAT") data.push(body);
    at += 12 + length;
  }
  const channels = type === 6 ? 4 : 3;
  const raw = inflateSync(Buffer.concat(data));
  const stride = width * channels;
  const out = Buffer.alloc(width * height * 4);
  const line = Buffer.alloc(stride);
  const previous = Buffer.alloc(stride);
  for (let y = 0; y < height; y++) {
    const filter = raw[y * (stride + 1)];
    const row = raw.subarray(y * (stride + 1) + 1, (y + 1) * (stride + 1));
    for (let x = 0; x < stride; x++) {
      const a = x >= channels ? line[x - channels] : 0;
      const b = previous[x];
      const c = x >= channels ? previous[x - channels] : 0;
      const p = a + b - c;
      const [pa, pb, pc] = [Math.abs(p - a), Math.abs(p - b), Math.abs(p - c)];
      const predictor = [0, a, b, (a + b) >> 1, pa <= pb && pa <= pc ? a : pb <= pc ? b : c][filter];
      line[x] = (row[x] + predictor) & 255;
    }
    line.copy(previous);
    for (let x = 0; x < width; x++) {
      for (let k = 0; k < 3; k++) out[(y * width + x) * 4 + k] = line[x * channels + k];
      out[(y * width + x) * 4 + 3] = 255;
    }
  }
  return { width, height, pixels: out };
}

// Counts the screenshot's pixels by colour: black, red lines, gray lines
// and near-white (the HUD's text) inside `box` ([x0, y0, x1, y1]), and
// `tinted`: any trace of red, a red line's even under a dark veil.
// With WEB_TEST_SHOTS set, each screenshot is also saved there as NAME.png.
async function colours(name, box) {
  const png = await browser.screenshot();
  if (process.env.WEB_TEST_SHOTS) writeFileSync(join(process.env.WEB_TEST_SHOTS, `${name}.png`), png);
  const { width, height, pixels } = decodePng(png);
  const [x0, y0, x1, y1] = box ?? [0, 0, width, height];
  const counts = { black: 0, red: 0, gray: 0, white: 0, tinted: 0, all: 0 };
  for (let y = y0; y < Math.min(y1, height); y++) {
    for (let x = x0; x < Math.min(x1, width); x++) {
      const [r, g, b] = pixels.subarray((y * width + x) * 4, (y * width + x) * 4 + 3);
      counts.all += 1;
      if (r > g + 20 && r > b + 20) counts.tinted += 1;
      if (r < 8 && g < 8 && b < 8) counts.black += 1;
      else if (r > 60 && r > g + 50 && r > b + 50) counts.red += 1;
      else if (r > 230 && g > 230 && b > 230) counts.white += 1;
      else if (r > 60 && Math.abs(r - g) < 12 && Math.abs(g - b) < 12) counts.gray += 1;
    }
  }
  return counts;
}

// ---- the checks ----------------------------------------------------------

let passed = 0;
let failed = 0;
// WEB_TEST_ONLY (a regular expression): only the checks it finds in their names.
const only = process.env.WEB_TEST_ONLY ? new RegExp(process.env.WEB_TEST_ONLY) : null;
async function check(name, body) {
  if (only && !only.test(name)) return;
  const started = Date.now();
  try {
    const detail = await body();
    passed += 1;
    console.log(`ok   ${name}${detail ? `: ${detail}` : ""} (${((Date.now() - started) / 1000).toFixed(1)} s)`);
  } catch (e) {
    failed += 1;
    console.log(`FAIL ${name}: ${e.message}`);
  }
}

const withoutTime = (text) => text.split("\n").filter((l) => !l.startsWith("Elapsed execution time")).join("\n");
const results = () => until("#results", () => textOf("results"));
const stepOf = () => run("return Number(document.body.dataset.step ?? -1);");
// The scene chooser's choice as shown (a file on show: its name).
const chosen = () => run("const k = document.getElementById('kind'); return k.options[k.selectedIndex].text;");
// The link's target (null: none) and its text.
const link = () => run("const a = document.getElementById('link'); return [a.getAttribute('href'), a.textContent];");
// Opens a file from disk through the "Open .in" button.
async function openFromDisk(path) {
  const input = await call("POST", session("/element"), { using: "css selector", value: "#file" });
  await call("POST", session(`/element/${Object.values(input)[0]}/value`), { text: path });
}
// The native binary's error for a scene file, as the page shows it:
// `path` relative to scratchRoot, as the page's URL names it.
function nativeError(path) {
  try {
    execFileSync(native, ["10", path], { cwd: scratchRoot, encoding: "utf8", stdio: "pipe" });
  } catch (e) {
    return e.stderr.trim().replace(/^screensaver: error: /, "");
  }
  throw new Error(`the native binary ran ${path}`);
}
// Two scenes with a mistake in the last row: a colour of 7, a missing comma.
const BAD = {
  "bad-colour.in": "2\n(300.0, 300.0), (344.0, 344.0), -0.26, -0.26, 0\n(302.0, 300.0), (320.0, 342.0), -0.26, -0.26, 7\n",
  "bad-comma.in": "2\n(300.0, 300.0), (344.0, 344.0), -0.26, -0.26, 0\n(302.0, 300.0) (320.0, 342.0), -0.26, -0.26, 1\n",
};
for (const [name, text] of Object.entries(BAD)) writeFileSync(join(scratch, name), text);

await check("a generated scene gives the native binary's text", async () => {
  const args = ["--lines", "2000", "--kind", "uniform", "--seed", "7", "300"];
  await open("?lines=2000&kind=uniform&seed=7&frames=300");
  const got = withoutTime(await results());
  const want = withoutTime(execFileSync(native, args, { encoding: "utf8" }));
  if (got.trim() !== want.trim()) throw new Error(`page:\n${got}\nnative:\n${want}`);
  return got.split("\n").slice(-4, -2).join(", ");
});

const scenes = ["beaver", "box", "explosion", "koch", "mit", "sin_wave", "smalllines"]
  .filter((name) => existsSync(join(reference, "inputs", `${name}.in`)));
if (scenes.length === 0) throw new Error(`no course scenes in ${reference}/inputs`);
for (const name of scenes) {
  const frames = 1000;
  await check(`${name}.in served by URL, ${frames} frames: the reference's counts`, async () => {
    const rows = readFileSync(join(reference, "expected", `${name}.counts.csv`), "utf8").trim().split("\n");
    const row = rows.find((r) => r.startsWith(`${frames + 1},`));
    const [, wall, line] = row.split(",").map(Number);
    await open(`?scene=reference/inputs/${name}.in&frames=${frames}&speed=max`);
    const got = await results();
    const want = `${wall} Line-Wall Collisions\n${line} Line-Line Collisions`;
    if (!got.includes(want)) throw new Error(`page:\n${got}\nreference: ${wall}, ${line}`);
    return `${wall}, ${line}`;
  });
}

// A scene's picture: mostly black, with enough red and gray pixels.
for (const [lines, query, shot, black, each] of [
  ["1,000 lines (the browser's strokes)", "", "built-in", 0.8, 500],
  ["20,000 lines (the project's rasteriser)", "?lines=20000&kind=clustered&seed=7", "clustered-20000", 0.5, 2000],
]) {
  await check(`the picture: both colours on black, ${lines}`, async () => {
    await open(query);
    await until("steps", async () => (await stepOf()) > 2);
    const c = await colours(shot);
    if (c.black < c.all * black || c.red < each || c.gray < each) throw new Error(JSON.stringify(c));
    return `black ${c.black}, red ${c.red}, gray ${c.gray}`;
  });
}

await check("the HUD shows when asked, and only then", async () => {
  const corner = [0, 0, 160, 90];
  await open("");
  await until("steps", async () => (await stepOf()) > 2);
  const without = await colours("without-hud", corner);
  await open("?hud=1");
  await until("steps", async () => (await stepOf()) > 2);
  const hud = await textOf("hud");
  const withHud = await colours("hud", corner);
  if (!/^step \d+\n\d+ line-wall\n\d+ line-line\n/.test(hud ?? "")) throw new Error(`HUD text: ${hud}`);
  if (withHud.white < 100 || without.white > 0) {
    throw new Error(`white pixels in the corner: ${withHud.white} with, ${without.white} without`);
  }
  return `${withHud.white} white pixels in the corner with it, ${without.white} without`;
});

await check("a bad .in file shows the command line's message and the page keeps running", async () => {
  const folder = mkdtempSync(join(tmpdir(), "screensaver-web-"));
  const bad = join(folder, "bad.in");
  writeFileSync(bad, "2\n(300.0, 300.0), (344.0, 344.0), -0.26, -0.26, 0\n(302.0, 300.0), (zz, 342.0), -0.26, -0.26, 1\n");
  let want = "";
  try {
    execFileSync(native, ["10", "bad.in"], { cwd: folder, encoding: "utf8", stdio: "pipe" });
  } catch (e) {
    want = e.stderr.trim().replace(/^screensaver: error: /, "");
  }
  if (!want.startsWith("bad.in:3:")) throw new Error(`the native binary said: ${want}`);
  await open("");
  await openFromDisk(bad);
  const got = await until("#error", () => textOf("error"));
  if (got !== want) throw new Error(`page: ${got}\nnative: ${want}`);
  const before = await stepOf();
  await until("more steps", async () => (await stepOf()) > before + 10, 20);
  return got;
});

await check("a .in file dropped on the page runs, and its run ends with the results block", async () => {
  await open("?frames=20&speed=max");
  await results();
  const scene = readFileSync(join(reference, "inputs", "beaver.in"), "utf8");
  await run(`
    const transfer = new DataTransfer();
    transfer.items.add(new File([arguments[0]], "beaver.in"));
    document.dispatchEvent(new DragEvent("drop", { dataTransfer: transfer, bubbles: true }));`, scene);
  const got = await until("the dropped scene's results", async () => {
    const text = await textOf("results");
    return text?.includes("Input file path is: beaver.in") ? text : null;
  });
  const rows = readFileSync(join(reference, "expected", "beaver.counts.csv"), "utf8").trim().split("\n");
  const [, wall, line] = rows.find((r) => r.startsWith("21,")).split(",").map(Number);
  if (!got.includes(`${wall} Line-Wall Collisions\n${line} Line-Line Collisions`)) throw new Error(got);
  const shown = await chosen();
  if (shown !== "beaver.in") throw new Error(`the scene chooser shows ${shown}`);
  return `beaver.in, 20 frames: ${wall}, ${line}`;
});

await check("a cycle of generated scenes moves on to the next", async () => {
  await open("?lines=300&cycle=1&hud=1");
  const hud = await until("a second scene", async () => {
    const text = await textOf("hud");
    return text?.includes("scene 2") ? text : null;
  }, 20);
  const kind = await run("return document.getElementById('kind').value;");
  if (kind !== "clustered") throw new Error(`the second scene is ${kind}, not the second kind`);
  return hud.split("\n").at(-1) + `, ${kind}`;
});

await check("the window's keys: Space pauses, Right arrow steps, - sets a pace, H hides the HUD", async () => {
  const key = (k) => run("document.dispatchEvent(new KeyboardEvent('keydown', { key: arguments[0] }));", k);
  await open("?hud=1");
  await until("steps", async () => (await stepOf()) > 3, 20);
  await key(" ");
  await sleep(200);
  const paused = await stepOf();
  await sleep(500);
  if ((await stepOf()) !== paused) throw new Error("the run went on while paused");
  await key("ArrowRight");
  await until("one step", async () => (await stepOf()) === paused + 1, 10);
  await sleep(300);
  if ((await stepOf()) !== paused + 1) throw new Error("Right arrow ran more than one step");
  await key("-");
  const slower = await until("a pace in the HUD", async () => {
    const hud = await textOf("hud");
    return /pace: \d+ steps\/s max/.test(hud ?? "") ? hud : null;
  }, 10);
  await key("h");
  await until("the HUD hidden", async () => (await textOf("hud")) === null, 10);
  await key(" ");
  await until("steps again", async () => (await stepOf()) > paused + 3, 20);
  return `paused at step ${paused}, one step on, ${slower.split("\n").at(-1)}`;
});

await check("+ after single steps in a pause doubles the running pace, not the paused one", async () => {
  const key = (k) => run("document.dispatchEvent(new KeyboardEvent('keydown', { key: arguments[0] }));", k);
  await open("?hud=1");
  await until("steps", async () => (await stepOf()) > 60, 20);
  await key(" ");
  // Longer than the rate's window, so that only the pause's steps are in it.
  await sleep(1200);
  for (let k = 0; k < 2; k++) {
    await key("ArrowRight");
    await sleep(600);
  }
  await key("+");
  const pace = await until("a pace in the HUD", async () => {
    const m = /pace: (\d+) steps\/s max/.exec((await textOf("hud")) ?? "");
    return m ? Number(m[1]) : null;
  }, 10);
  // One step a picture runs tens of steps a second; doubled, more still.
  if (pace < 20) throw new Error(`+ after a pause set ${pace} steps/s`);
  return `${pace} steps/s`;
});

await check("a broken scene given by URL shows its located error, over the built-in scene named as what runs", async () => {
  const seen = [];
  for (const name of Object.keys(BAD)) {
    const want = nativeError(`scratch/${name}`);
    if (!want.startsWith(`scratch/${name}:3: row 2:`)) throw new Error(`the native binary said: ${want}`);
    await open(`?scene=scratch/${name}&frames=5&speed=max`);
    // The run's end first: the error must still be there after it.
    const got = await results();
    const error = await textOf("error");
    if (error === null || error.split("\n")[0] !== want) throw new Error(`page's error: ${error}\nnative: ${want}`);
    if (!error.includes("The built-in scene is on show instead.")) throw new Error(`page's error: ${error}`);
    if (got.includes(name) || !got.includes("Input file path is: (none: built-in")) throw new Error(`results:\n${got}`);
    const [href] = await link();
    if (href?.includes("scene=")) throw new Error(`the link names the file that did not run: ${href}`);
    const overlap = await run(`
      const [e, r] = ["error", "results"].map((id) => document.getElementById(id).getBoundingClientRect());
      return e.left < r.right && r.left < e.right && e.top < r.bottom && r.top < e.bottom;`);
    if (overlap) throw new Error("the error and the results block cover each other");
    seen.push(want);
  }
  return seen.join("; ");
});

await check("the link follows what is on show: a file from disk has none, a URL scene and a form's scene reproduce", async () => {
  const wait = 30;
  // The issue's steps: a broken scene by URL, then a good file from disk.
  await open("?scene=scratch/bad-colour.in");
  await until("steps", async () => (await stepOf()) > 2, wait);
  await openFromDisk(join(reference, "inputs", "box.in"));
  await until("box.in on show", async () => (await chosen()) === "box.in", wait);
  const [fromDisk, word] = await link();
  if (fromDisk !== null || !word.includes("no link")) throw new Error(`file from disk: link ${fromDisk}, "${word}"`);
  // A scene by URL, then a generated one from the form: each link names it.
  await open("?scene=reference/inputs/koch.in&speed=max");
  await until("koch on show", async () => (await chosen()) === "reference/inputs/koch.in", wait);
  const [byUrl] = await link();
  if (new URLSearchParams(byUrl).get("scene") !== "reference/inputs/koch.in") throw new Error(`URL scene: link ${byUrl}`);
  await run(`
    for (const [id, value] of [["kind", "ring"], ["lines", "300"], ["seed", "9"], ["cycle", "0"]]) {
      document.getElementById(id).value = value;
    }
    document.querySelector("[data-action=run]").click();`);
  // The form names the ring at once (the test filled it in); the world on
  // show is the ring once the worker has started it, after the steps it
  // was running, and then the link names it.
  await until("the ring on show", async () => {
    const [href] = await link();
    return (await chosen()) === "ring" && new URLSearchParams(href).get("kind") === "ring";
  }, wait);
  const [generated] = await link();
  const p = new URLSearchParams(generated);
  if (p.get("scene") !== null || p.get("kind") !== "ring" || p.get("lines") !== "300" || p.get("seed") !== "9"
    || p.get("speed") !== "max") {
    throw new Error(`generated scene: link ${generated}`);
  }
  // Followed, the link shows the same scene.
  await open(generated);
  await until("the link's scene", async () => (await chosen()) === "ring", wait);
  const form = await run("return ['lines', 'seed'].map((id) => document.getElementById(id).value).join(' ');");
  if (form !== "300 9") throw new Error(`the link's scene has lines and seed ${form}`);
  return `from disk: "${word}"; ${byUrl}; ${generated}`;
});

await check("the form refuses what is out of range and says so, and the run on show goes on", async () => {
  const wait = 30;
  const fill = (values) => run(`
    for (const [id, value] of arguments[0]) document.getElementById(id).value = value;
    document.querySelector("[data-action=run]").click();`, values);
  await open("");
  await until("steps", async () => (await stepOf()) > 2, wait);
  const [onShow] = await link();
  const said = [];
  for (const [values, want] of [
    [[["kind", "uniform"], ["lines", "-5"], ["seed", "1"], ["cycle", "0"]],
      ["lines -5: expected a whole number from 1 to 1000000"]],
    [[["lines", "5000000"]], ["lines 5000000: expected a whole number from 1 to 1000000"]],
    [[["lines", "2.5"], ["seed", "-1"], ["cycle", "-3"]],
      ["lines 2.5: expected a whole number", "seed -1: expected a whole number below 2^64",
        "cycle -3: expected a number from 0 to"]],
  ]) {
    const step = await stepOf();
    await fill(values);
    const error = await until("the form's error", () => textOf("error"), wait);
    for (const w of want) if (!error.includes(w)) throw new Error(`page's error: ${error}\nexpected: ${w}`);
    // The world on show is the same: its link, and its steps go on from where they were.
    const [now] = await link();
    if (now !== onShow || (await stepOf()) < step) throw new Error(`a new run started: link ${now}`);
    said.push(error.replaceAll("\n", "; "));
    await run("document.getElementById('error').hidden = true;");
  }
  const before = await stepOf();
  await until("more steps", async () => (await stepOf()) > before + 5, wait);
  // A good form runs its scene and clears the message.
  await fill([["lines", "300"], ["seed", "9"], ["cycle", "0"]]);
  await until("the uniform scene", async () => (await chosen()) === "uniform", wait);
  if ((await textOf("error")) !== null) throw new Error(`an error after a good form: ${await textOf("error")}`);
  return said.join(" | ");
});

// Over every load so far: the browser asks for a missing favicon once.
await check("no page load has asked for anything the server lacks (the favicon is inline)", async () => {
  await open("?frames=3");
  await results();
  await sleep(2000); // the browser asks for a favicon after the page has loaded
  if (browser.missing.length) throw new Error(`404 for ${browser.missing.join(", ")}`);
  return "no 404";
});

await check("the results block is opaque over the lines", async () => {
  await open("?lines=20000&kind=uniform&seed=7&frames=3&speed=max");
  await results();
  await sleep(300); // the last picture drawn
  const [x0, y0, x1, y1] = await run(`
    const r = document.getElementById("results").getBoundingClientRect();
    return [r.left, r.top, r.right, r.bottom].map(Math.round);`);
  const inside = await colours("results", [x0 + 2, y0 + 2, x1 - 2, y1 - 2]);
  const below = await colours("results-below", [x0, y1 + 2, x1, y1 + 100]);
  if (below.tinted < 100) throw new Error(`the check needs lines under the block: ${JSON.stringify(below)}`);
  if (inside.tinted > 0) throw new Error(`a red line shows through the block: ${JSON.stringify(inside)}`);
  return `${inside.all} pixels inside, none red; ${below.tinted} red below`;
});

await check("a bad detector in the URL lists the detectors as the command line does", async () => {
  await open("?detector=magic");
  const shown = await until("the problem shown", async () => {
    const t = await textOf("error");
    return t && t.includes("detector=magic") ? t : null;
  }, 10);
  // The command line's list, in the one order of the library's detectors.
  const message = spawnSync(native, ["1", "--detector", "magic"], { encoding: "utf8" }).stderr;
  const list = /expected one of: ([a-z, ]+)/.exec(message)?.[1];
  if (!list) throw new Error(`no list in the command line's message: ${message}`);
  if (!shown.includes(`expected one of ${list}`)) throw new Error(`${shown} against the command line's ${list}`);
  return list;
});

await check("a bad URL parameter is named on the page, and the page runs the built-in scene", async () => {
  await open("?kind=spiral");
  const got = await until("#error", () => textOf("error"));
  if (!got.includes("kind=spiral")) throw new Error(got);
  await until("steps", async () => (await stepOf()) > 2, 20);
  return got;
});

await check("a bad speed in the URL is named with what it should be: its range, frame or max", async () => {
  const seen = [];
  for (const speed of ["fast", "0", "2000000"]) {
    await open(`?speed=${speed}`);
    const shown = await until("the problem shown", async () => {
      const t = await textOf("error");
      return t && t.includes(`speed=${speed}`) ? t : null;
    }, 10);
    for (const want of ["from 1 to 1048576", "frame", "max"]) {
      if (!shown.includes(want)) throw new Error(`${shown}\nexpected: ${want}`);
    }
    seen.push(shown.split("\n")[0]);
  }
  return seen[0];
});

await check("hud=yes, on and true show the HUD, off hides it, and another value is named", async () => {
  for (const spelling of ["yes", "on", "true"]) {
    await open(`?hud=${spelling}`);
    await until("steps", async () => (await stepOf()) > 2, 20);
    const hud = await textOf("hud");
    if (!/^step \d+\n/.test(hud ?? "")) throw new Error(`hud=${spelling}: HUD text ${hud}`);
    const error = await textOf("error");
    if (error !== null) throw new Error(`hud=${spelling}: ${error}`);
  }
  await open("?hud=off");
  await until("steps", async () => (await stepOf()) > 2, 20);
  if ((await textOf("hud")) !== null) throw new Error("hud=off shows the HUD");
  await open("?hud=maybe");
  const shown = await until("the problem shown", async () => {
    const t = await textOf("error");
    return t && t.includes("hud=maybe") ? t : null;
  }, 10);
  if (!shown.includes("expected 1")) throw new Error(shown);
  await until("steps", async () => (await stepOf()) > 2, 20);
  if ((await textOf("hud")) !== null) throw new Error("hud=maybe shows the HUD");
  return shown;
});

await check("lines, seed and cycle are off, and say why, while the built-in scene is chosen, and on for a kind", async () => {
  // Each field: [disabled, its label's title].
  const fields = () => run(`return ["lines", "seed", "cycle"].map((id) => {
    const input = document.getElementById(id);
    return [input.disabled, input.closest("label").title];
  });`);
  const choose = (kind) => run(`
    const k = document.getElementById("kind");
    k.value = arguments[0];
    k.dispatchEvent(new Event("change", { bubbles: true }));`, kind);
  const off = (list) => list.every(([disabled, title]) => disabled && title.includes("generated scenes only"));
  const on = (list) => list.every(([disabled, title]) => !disabled && !title.includes("generated scenes only"));
  await open("");
  await until("steps", async () => (await stepOf()) > 2, 20);
  const builtIn = await fields();
  if (!off(builtIn)) throw new Error(`built-in: ${JSON.stringify(builtIn)}`);
  await choose("ring");
  if (!on(await fields())) throw new Error(`ring chosen: ${JSON.stringify(await fields())}`);
  await choose("built-in");
  if (!off(await fields())) throw new Error(`built-in chosen again: ${JSON.stringify(await fields())}`);
  // A generated scene by URL: on from the start.
  await open("?lines=300");
  await until("the uniform scene", async () => (await chosen()) === "uniform", 20);
  if (!on(await fields())) throw new Error(`?lines=300: ${JSON.stringify(await fields())}`);
  return builtIn[0][1];
});

await check("a scene on another origin is named, with why: the page's origin, or CORS", async () => {
  await open("");
  const origin = await run("return location.origin;");
  // The same server under another name: another origin, which sends no CORS header.
  const other = origin.replace("127.0.0.1", "localhost");
  if (other === origin) throw new Error(`the page is not on 127.0.0.1: ${origin}`);
  const url = `${other}/reference/inputs/box.in`;
  await open(`?scene=${encodeURIComponent(url)}`);
  const shown = await until("the problem shown", async () => {
    const t = await textOf("error");
    return t && t.includes(url) ? t : null;
  }, 20);
  for (const want of ["another origin", origin, "CORS", "The built-in scene is on show instead."]) {
    if (!shown.includes(want)) throw new Error(`${shown}\nexpected: ${want}`);
  }
  await until("steps", async () => (await stepOf()) > 2, 20);
  return shown.split("\n")[0];
});

await browser.close();
rmSync(scratchRoot, { recursive: true, force: true });
console.log(`${passed} passed, ${failed} failed`);
process.exit(failed === 0 ? 0 : 1);
