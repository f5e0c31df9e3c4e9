// Plays .glb files in three.js inside headless Chromium and saves what it
// draws, for the end-to-end tests (app/tests/browser.rs).
//
//   node render.mjs JOB.json
//
// JOB.json: { "width": W, "height": H, "times": [seconds, ...],
//   "camera": { "eye": [x,y,z], "target": [x,y,z], "up": [x,y,z],
//               "vertical_fov_deg": F, "near": N },
//   "hide": [mesh names left out of the ids picture],
//   "shape_times": [seconds, ...] (optional: compare every vertex and
//     normal at these times with the first file's, see page.html),
//   "files": [{ "name": "dense", "path": "/abs/lily-dense.glb" }, ...],
//   "out": "/abs/folder" }
//
// Writes OUT/NAME-I-shaded.png (the file's materials on magenta) and
// OUT/NAME-I-ids.png (one flat colour per mesh on black) for time I, and
// prints a JSON report: browser and three.js versions, the console errors
// and warnings, page errors and failed requests, and per file its meshes,
// morph target counts, animations, per time the pixels of each mesh, and
// (from the second file on) the largest position and normal differences
// from the first file at the shape times.
//
// Uses Debian's Chromium (/usr/bin/chromium, or CHROMIUM) with software
// WebGL (SwiftShader); never downloads a browser. Exit status: 0 when a
// report was printed, 2 on bad usage, 3 when the browser failed.
import { readFile, writeFile } from "node:fs/promises";
import { createServer } from "node:http";
import { dirname, join, normalize } from "node:path";
import { fileURLToPath } from "node:url";
import puppeteer from "puppeteer-core";

const here = dirname(fileURLToPath(import.meta.url));
const jobPath = process.argv[2];
if (!jobPath || process.argv.length > 3) {
  console.error("usage: node render.mjs JOB.json");
  process.exit(2);
}
const job = JSON.parse(await readFile(jobPath, "utf8"));

// A server on the loopback interface only: the page, three.js, the files.
const threeRoot = join(here, "node_modules", "three");
const types = { ".html": "text/html", ".js": "text/javascript", ".glb": "model/gltf-binary" };
const server = createServer(async (request, response) => {
  const url = decodeURIComponent(new URL(request.url, "http://localhost").pathname);
  let path = null;
  if (url === "/") path = join(here, "page.html");
  else if (url.startsWith("/three/")) {
    const inside = normalize(join(threeRoot, url.slice("/three/".length)));
    if (inside.startsWith(threeRoot)) path = inside;
  } else if (url.startsWith("/files/")) {
    const file = job.files.find((f) => f.name === url.slice("/files/".length));
    if (file) path = file.path;
  }
  try {
    if (!path) throw new Error("not served");
    const body = await readFile(path);
    const ext = path.slice(path.lastIndexOf("."));
    response.writeHead(200, { "content-type": types[ext] ?? "application/octet-stream" });
    response.end(body);
  } catch {
    response.writeHead(404);
    response.end();
  }
});
await new Promise((resolve) => server.listen(0, "127.0.0.1", resolve));
const origin = `http://127.0.0.1:${server.address().port}`;

const messages = [];
let browser;
try {
  browser = await puppeteer.launch({
    executablePath: process.env.CHROMIUM || "/usr/bin/chromium",
    headless: true,
    args: [
      "--no-sandbox",
      "--disable-gpu",
      "--disable-background-networking",
      "--disable-component-update",
      "--disable-sync",
      "--no-first-run",
      // WebGL on the CPU: Chromium's bundled SwiftShader.
      "--use-angle=swiftshader",
      "--enable-unsafe-swiftshader",
    ],
  });
  const page = await browser.newPage();
  page.on("console", (m) => {
    if (m.type() === "error" || m.type() === "warn" || m.type() === "warning") {
      messages.push({ kind: m.type() === "error" ? "error" : "warning", text: m.text() });
    }
  });
  page.on("pageerror", (e) => messages.push({ kind: "error", text: `page error: ${e.message}` }));
  page.on("requestfailed", (r) => messages.push({ kind: "error", text: `request failed: ${r.url()}` }));
  page.on("response", (r) => {
    if (r.status() >= 400) messages.push({ kind: "error", text: `HTTP ${r.status()}: ${r.url()}` });
  });
  await page.goto(`${origin}/`);
  await page.waitForFunction("window.pageReady === true", { timeout: 30000 });

  const files = [];
  for (const [index, file] of job.files.entries()) {
    const spec = {
      width: job.width, height: job.height, times: job.times, camera: job.camera, hide: job.hide ?? [],
      shape_times: job.shape_times ?? [], reference: index === 0,
    };
    let report;
    try {
      report = await page.evaluate(
        (url, spec) => window.renderFile(url, spec),
        `${origin}/files/${encodeURIComponent(file.name)}`,
        spec,
      );
    } catch (error) {
      messages.push({ kind: "error", text: `${file.name}: ${error.message}` });
      files.push({ name: file.name, failed: true });
      continue;
    }
    for (const [i, frame] of report.frames.entries()) {
      for (const kind of ["shaded", "ids"]) {
        const png = Buffer.from(frame[kind].replace(/^data:image\/png;base64,/, ""), "base64");
        const path = join(job.out, `${file.name}-${i}-${kind}.png`);
        await writeFile(path, png);
        frame[kind] = path;
      }
    }
    files.push({ name: file.name, ...report });
  }
  const version = await browser.version();
  console.log(JSON.stringify({ browser: version, messages, files }, null, 1));
} catch (error) {
  console.error(`the browser check failed: ${error.stack ?? error}`);
  process.exitCode = 3;
} finally {
  if (browser) await browser.close();
  server.close();
}
