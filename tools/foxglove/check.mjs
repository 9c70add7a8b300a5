// Opens an a2ml MCAP with a Foxglove layout in Foxglove Studio's web build
// (@foxglove/studio-base, served from node_modules), in headless Chromium, and
// writes screenshots and the browser's console to out/.
//
//   node check.mjs PLAN.mcap [LAYOUT.json] [--chromium PATH] [--out DIR]
//
// The MCAP is opened the way a user opens a file by URL
// (?ds=remote-file&ds.url=...), served with HTTP range requests, which is how
// Foxglove reads a remote MCAP; the layout is the one stored layout, which is
// what "Import from file" leaves behind.
import { createReadStream, mkdirSync, readFileSync, statSync, writeFileSync } from "node:fs";
import { createServer } from "node:http";
import { dirname, extname, join, resolve } from "node:path";
import { fileURLToPath } from "node:url";
import { chromium } from "playwright-core";

const here = dirname(fileURLToPath(import.meta.url));
const repo = resolve(here, "../..");

function parseArguments(argv) {
  const options = {
    mcap: undefined,
    layout: join(repo, "docs/foxglove_layout.json"),
    chromium: "/usr/bin/chromium",
    out: join(here, "out"),
  };
  const positional = [];
  for (let i = 0; i < argv.length; i++) {
    if (argv[i] === "--chromium") options.chromium = argv[++i];
    else if (argv[i] === "--out") options.out = argv[++i];
    else positional.push(argv[i]);
  }
  if (positional.length < 1 || positional.length > 2) {
    throw new Error("usage: node check.mjs PLAN.mcap [LAYOUT.json] [--chromium PATH] [--out DIR]");
  }
  options.mcap = resolve(positional[0]);
  if (positional[1]) options.layout = resolve(positional[1]);
  return options;
}

const CONTENT_TYPES = {
  ".html": "text/html",
  ".js": "text/javascript",
  ".json": "application/json",
  ".wasm": "application/wasm",
  ".png": "image/png",
  ".ttf": "font/ttf",
  ".mcap": "application/octet-stream",
};

// URL prefix -> directory or file it is served from.
function routes(options) {
  const modules = join(here, "node_modules");
  return [
    ["/react/", join(modules, "react/")],
    ["/react-dom/", join(modules, "react-dom/")],
    ["/studio/", join(modules, "@foxglove/studio-base/assets/")],
    ["/root.js", join(here, "root.js")],
    ["/layout.json", options.layout],
    ["/plan.mcap", options.mcap],
    ["/", join(here, "index.html")],
  ];
}

function resolveFile(table, urlPath) {
  for (const [prefix, target] of table) {
    if (prefix.endsWith("/") && prefix !== "/" && urlPath.startsWith(prefix)) {
      const file = resolve(target, "." + urlPath.slice(prefix.length - 1));
      return file.startsWith(target) ? file : undefined;
    }
    if (urlPath === prefix) return target;
  }
  return undefined;
}

// Paths the viewer asked for that the server does not have, for the console log.
const notFound = [];

// Serves the files with range requests (Foxglove's remote MCAP reader asks for
// byte ranges) and CORS, on 127.0.0.1 at a free port.
function serve(options) {
  const table = routes(options);
  const server = createServer((request, response) => {
    const urlPath = decodeURIComponent(new URL(request.url, "http://localhost").pathname);
    const file = resolveFile(table, urlPath);
    let size;
    try {
      size = file && statSync(file).isFile() ? statSync(file).size : undefined;
    } catch {
      size = undefined;
    }
    if (size === undefined) {
      notFound.push(urlPath);
      response.writeHead(404).end();
      return;
    }
    const headers = {
      "Content-Type": CONTENT_TYPES[extname(file)] ?? "application/octet-stream",
      "Accept-Ranges": "bytes",
      "Access-Control-Allow-Origin": "*",
      "Access-Control-Expose-Headers": "Accept-Ranges, Content-Length, Content-Range",
      "Cache-Control": "no-store",
    };
    const range = /^bytes=(\d*)-(\d*)$/.exec(request.headers.range ?? "");
    if (range) {
      const start = range[1] === "" ? Math.max(0, size - Number(range[2])) : Number(range[1]);
      const end = range[1] !== "" && range[2] !== "" ? Math.min(Number(range[2]), size - 1) : size - 1;
      if (start > end || start >= size) {
        response.writeHead(416, { ...headers, "Content-Range": `bytes */${size}` }).end();
        return;
      }
      response.writeHead(206, {
        ...headers,
        "Content-Range": `bytes ${start}-${end}/${size}`,
        "Content-Length": end - start + 1,
      });
      if (request.method === "HEAD") response.end();
      else createReadStream(file, { start, end }).pipe(response);
      return;
    }
    response.writeHead(200, { ...headers, "Content-Length": size });
    if (request.method === "HEAD") response.end();
    else createReadStream(file).pipe(response);
  });
  return new Promise((done) => server.listen(0, "127.0.0.1", () => done(server)));
}

// The panel ids of a layout file ("3D!a2ml", "Plot!joint1", ...).
function layoutPanels(layoutFile) {
  return Object.keys(JSON.parse(readFileSync(layoutFile, "utf8")).configById);
}

const SETTLE_MS = Number(process.env.A2ML_SETTLE_MS ?? 8000);
const SCREENSHOT = { timeout: 180000 };

// Waits for the layout's panels, then seeks to a few instants and takes a
// screenshot of the window and of the 3D panel at each, and one of the 3D
// panel's settings (its topics and layers, with any error Foxglove reports).
async function view(page, options, panels) {
  for (const panel of panels) {
    await page
      .getByTestId(`panel-mouseenter-container ${panel}`)
      .waitFor({ timeout: 180000 })
      .catch(() => {
        throw new Error(`panel ${panel} of the layout is not shown`);
      });
  }
  const threeDee = page.getByTestId(`panel-mouseenter-container ${panels.find((p) => p.startsWith("3D!"))}`);
  await threeDee.locator("canvas").first().waitFor({ timeout: 180000 });
  // The first-run hint over the 3D panel's toolbar.
  const hint = page.getByText("Open settings to configure topics and layers.");
  // A dispatched click: the hint fades in, and under load it may never look stable.
  if (await hint.isVisible()) {
    await hint.locator("..").getByRole("button", { name: "Dismiss" }).dispatchEvent("click");
  }
  // The playback slider is disabled until the MCAP's summary is read.
  const slider = page.locator('[class*="-Slider-root"]:not([class*="rootDisabled"])').first();
  await slider.waitFor({ timeout: 180000 });
  for (const fraction of [0.02, 0.35, 0.75, 0.99]) {
    const box = await slider.boundingBox();
    await slider.click({ position: { x: box.width * fraction, y: box.height / 2 } });
    // Away from the slider, whose hover label would cover the panels.
    await page.mouse.move(box.x + box.width / 2, box.y - 300);
    await page.waitForTimeout(SETTLE_MS);
    const name = `t${String(Math.round(fraction * 100)).padStart(2, "0")}`;
    await page.screenshot({ path: join(options.out, `window-${name}.png`), ...SCREENSHOT });
    await threeDee.screenshot({ path: join(options.out, `3d-${name}.png`), ...SCREENSHOT });
  }
  await threeDee.hover();
  await threeDee.getByTestId("SettingsIcon").first().click();
  await page.waitForTimeout(SETTLE_MS);
  await page.screenshot({ path: join(options.out, "3d-settings.png"), ...SCREENSHOT });
  const settings = await page.locator("body").innerText();
  writeFileSync(join(options.out, "3d-settings.txt"), settings);
  return settings;
}

// What a run must show: every topic the layout's 3D panel names listed in its
// settings (Foxglove found it in the MCAP), and no uncaught error in the page.
function problems(layoutFile, settings, console) {
  const found = [];
  const configs = JSON.parse(readFileSync(layoutFile, "utf8")).configById;
  for (const [id, config] of Object.entries(configs)) {
    if (!id.startsWith("3D!")) continue;
    for (const topic of Object.keys(config.topics ?? {})) {
      if (!settings.split("\n").includes(topic)) found.push(`${id}: topic ${topic} not in the 3D settings`);
    }
  }
  found.push(...console.filter((line) => line.startsWith("[pageerror]")));
  return found;
}

async function main() {
  const options = parseArguments(process.argv.slice(2));
  mkdirSync(options.out, { recursive: true });
  const server = await serve(options);
  const origin = `http://127.0.0.1:${server.address().port}`;
  const url = `${origin}/?ds=remote-file&ds.url=${encodeURIComponent(`${origin}/plan.mcap`)}`;
  const browser = await chromium.launch({
    executablePath: options.chromium,
    headless: true,
    // WebGL without a GPU: Chromium's software renderer.
    args: ["--use-angle=swiftshader", "--enable-unsafe-swiftshader", "--ignore-gpu-blocklist"],
  });
  const console = [];
  const failures = [];
  try {
    const page = await browser.newPage({ viewport: { width: 1600, height: 1000 } });
    page.on("console", (message) => console.push(`[${message.type()}] ${message.text()}`));
    page.on("pageerror", (error) => console.push(`[pageerror] ${error.message}`));
    page.on("response", (response) => {
      if (response.status() >= 400) console.push(`[http ${response.status()}] ${response.url()}`);
    });
    // The layout the user last chose is kept in the profile; this one chooses ours.
    await page.addInitScript(() => {
      window.localStorage.setItem("studio.profile-data", JSON.stringify({ currentLayoutId: "a2ml" }));
    });
    await page.goto(url, { timeout: 180000 });
    const settings = await view(page, options, layoutPanels(options.layout));
    failures.push(...problems(options.layout, settings, console));
  } finally {
    const served = notFound.map((path) => `[server 404] ${path}`);
    writeFileSync(join(options.out, "console.log"), [...console, ...served].join("\n") + "\n");
    await browser.close();
    server.close();
  }
  if (failures.length > 0) {
    throw new Error(`the viewer did not show the plan as the layout asks:\n${failures.join("\n")}`);
  }
  process.stdout.write(`ok: screenshots and console log in ${options.out}\n`);
}

main().catch((error) => {
  process.stderr.write(`${error.stack ?? error}\n`);
  process.exit(1);
});
