// Opens `tactex serve`'s page in headless Chromium, asks a question, waits for the answer,
// the detection overlay and every touched fruit's tactile frames, checks them, and saves a
// screenshot. Usage: node serve_page.mjs URL SCREENSHOT.png [PROMPT]
import { chromium } from "playwright-core";

const [url, screenshot, prompt = "Which fruit is the softest?"] = process.argv.slice(2);
if (!url || !screenshot) {
  console.error("usage: node serve_page.mjs URL SCREENSHOT.png [PROMPT]");
  process.exit(2);
}

const fail = (message) => {
  throw new Error(message);
};

const browser = await chromium.launch({
  executablePath: process.env.CHROMIUM || "/usr/bin/chromium",
  args: ["--headless", "--no-sandbox", "--disable-gpu", "--disable-background-networking",
    "--disable-component-update", "--disable-sync", "--no-first-run"],
});
try {
  const page = await browser.newPage({ viewport: { width: 1360, height: 1100 } });
  const errors = [];
  page.on("pageerror", (e) => errors.push(e.message));
  await page.goto(url);
  // The live view: a camera frame, loaded.
  await page.waitForFunction(() => {
    const v = document.getElementById("view");
    return v.complete && v.naturalWidth > 0;
  }, null, { timeout: 60_000 });

  await page.fill("#prompt", prompt);
  await page.click("#ask");
  await page.waitForSelector("#chat .msg.robot, #chat .msg.error", { timeout: 300_000 });
  const failed = await page.$("#chat .msg.error");
  if (failed) fail(`the page shows an error: ${await failed.textContent()}`);
  const answer = await page.textContent("#chat .msg.robot");

  const fruits = await page.$$eval(".fruit h3", (hs) => hs.map((h) => h.textContent));
  if (fruits.length === 0) fail("no touched fruit is shown");
  // Every tactile frame decoded by the browser.
  await page.waitForFunction(() => {
    const imgs = [...document.querySelectorAll("img.tactile, img.imprint")];
    return imgs.length > 0 && imgs.every((i) => i.complete && i.naturalWidth === 320);
  }, null, { timeout: 60_000 });
  const frames = await page.$$eval("img.tactile", (imgs) => imgs.length);
  if (frames !== 9 * fruits.length) fail(`${frames} tactile frames for ${fruits.length} fruits`);
  const imprints = await page.$$eval("img.imprint", (imgs) => imgs.length);
  if (imprints !== fruits.length) fail(`${imprints} imprints for ${fruits.length} fruits`);
  const boxes = await page.$$eval("#overlay rect", (rs) => rs.length);
  if (boxes !== fruits.length) fail(`${boxes} overlay boxes for ${fruits.length} fruits`);
  const bars = await page.$$eval(".fruit .hardness .mark", (ms) => ms.length);
  if (bars === 0) fail("no hardness bar");
  const latency = await page.$$eval("#latency tbody tr", (rs) => rs.length);
  if (latency < 5) fail(`latency table has ${latency} rows`);
  if (errors.length) fail(`script errors: ${errors.join("; ")}`);

  await page.screenshot({ path: screenshot, fullPage: true });
  console.log(JSON.stringify({ answer, fruits, frames, boxes, bars, latency_rows: latency }));
} finally {
  await browser.close();
}
