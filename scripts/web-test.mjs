// The web page's tests, in a real browser: Debian's headless Chromium
// driven through chromedriver (WebDriver over HTTP), the page served from
// 127.0.0.1 by this script, with ../shared/reference/inputs (or
// $SCREENSAVER_REFERENCE/inputs) served beside it under /reference/.
// Prints one line a check and `N passed, M failed`; exits 1 on a failure.
//
//   node scripts/web-test.mjs DIST_DIR NATIVE_BINARY
import { execFileSync } from "node:child_process";
import { readFileSync, existsSync, mkdtempSync, writeFileSync } from "node:fs";
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

const browser = await startBrowser({ dist, reference });
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
// and near-white (the HUD's text) inside `box` ([x0, y0, x1, y1]).
// With WEB_TEST_SHOTS set, each screenshot is also saved there as NAME.png.
async function colours(name, box) {
  const png = await browser.screenshot();
  if (process.env.WEB_TEST_SHOTS) writeFileSync(join(process.env.WEB_TEST_SHOTS, `${name}.png`), png);
  const { width, height, pixels } = decodePng(png);
  const [x0, y0, x1, y1] = box ?? [0, 0, width, height];
  const counts = { black: 0, red: 0, gray: 0, white: 0, all: 0 };
  for (let y = y0; y < Math.min(y1, height); y++) {
    for (let x = x0; x < Math.min(x1, width); x++) {
      const [r, g, b] = pixels.subarray((y * width + x) * 4, (y * width + x) * 4 + 3);
      counts.all += 1;
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
async function check(name, body) {
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
  const input = await call("POST", session("/element"), { using: "css selector", value: "#file" });
  const id = Object.values(input)[0];
  await call("POST", session(`/element/${id}/value`), { text: bad });
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
  const chosen = await run("const k = document.getElementById('kind'); return k.options[k.selectedIndex].text;");
  if (chosen !== "beaver.in") throw new Error(`the scene chooser shows ${chosen}`);
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

await check("a bad URL parameter is named on the page, and the page runs the built-in scene", async () => {
  await open("?kind=spiral");
  const got = await until("#error", () => textOf("error"));
  if (!got.includes("kind=spiral")) throw new Error(got);
  await until("steps", async () => (await stepOf()) > 2, 20);
  return got;
});

await browser.close();
console.log(`${passed} passed, ${failed} failed`);
process.exit(failed === 0 ? 0 : 1);
