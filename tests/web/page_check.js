// tests/web/page_check.js: opens pages of a built site in headless Chromium and prints what they said.
//   node page_check.js SITE_DIR CHROMIUM TIMEOUT_S [--screenshots=DIR] QUERY...
// Serves SITE_DIR on 127.0.0.1 (a free port, node's http module: a static server), starts CHROMIUM
// headless (SwiftShader WebGL 2) with the DevTools protocol on a pipe (fds 3 and 4: no port, no
// shell), and for each QUERY (e.g. "?lab=slider_crank&probe=1") loads index.html+QUERY in a fresh tab
// and prints every console line and uncaught exception as one JSON line
//   {"query": Q, "lines": [...], "exceptions": [...], "done": true|false}
// once a line starting "dynlab canvas:" or "dynlab results.json:" appeared (done) or TIMEOUT_S passed.
// With --screenshots=DIR, each page's PNG (DIR/page-N.png, N from 1) once it is done, for a person to look at.
// Exit 0 when the browser ran (what the pages said is for the caller to judge), 1 otherwise.
'use strict';
const http = require('http');
const fs = require('fs');
const os = require('os');
const path = require('path');
const { spawn } = require('child_process');

const [siteArg, chromium, timeoutText, ...rest] = process.argv.slice(2);
const site = path.resolve(siteArg || '.');  // a relative SITE_DIR too (the server compares resolved paths)
const shots = rest.length && rest[0].startsWith('--screenshots=') ? rest.shift().substring(14) : '';
const queries = rest;
const timeoutMs = Number(timeoutText) * 1000;
const types = { '.html': 'text/html', '.js': 'text/javascript', '.wasm': 'application/wasm', '.data': 'application/octet-stream', '.json': 'application/json' };

const server = http.createServer((req, res) => {
  const name = decodeURIComponent(new URL(req.url, 'http://x').pathname).replace(/^\/+/, '') || 'index.html';
  const file = path.join(site, name);
  if (!file.startsWith(path.resolve(site)) || !fs.existsSync(file) || !fs.statSync(file).isFile()) {
    res.writeHead(404);
    res.end();
    return;
  }
  res.writeHead(200, { 'Content-Type': types[path.extname(file)] || 'application/octet-stream' });
  fs.createReadStream(file).pipe(res);
});

function main(port) {
  const profile = fs.mkdtempSync(path.join(os.tmpdir(), 'dynlab-page-check-'));
  // --disable-dev-shm-usage: shared memory in /tmp, where a container's /dev/shm (64 MB) is too small.
  const browser = spawn(chromium, ['--headless', '--no-sandbox', '--disable-dev-shm-usage',
    '--enable-unsafe-swiftshader', '--use-angle=swiftshader',
    '--remote-debugging-pipe', '--user-data-dir=' + profile, '--window-size=1400,800', '--no-first-run',
    '--disable-background-timer-throttling', '--disable-renderer-backgrounding', 'about:blank'],
  { stdio: ['ignore', 'ignore', 'ignore', 'pipe', 'pipe'] });
  const toBrowser = browser.stdio[3], fromBrowser = browser.stdio[4];
  let nextId = 1, buffered = Buffer.alloc(0);
  const waiting = new Map(), listeners = [];
  function send(method, params = {}, sessionId) {
    const id = nextId++;
    toBrowser.write(JSON.stringify({ id, method, params, sessionId }) + '\0');
    return new Promise((resolve, reject) => waiting.set(id, { resolve, reject }));
  }
  fromBrowser.on('data', (chunk) => {
    buffered = Buffer.concat([buffered, chunk]);
    for (let end; (end = buffered.indexOf(0)) >= 0;) {
      const msg = JSON.parse(buffered.subarray(0, end).toString('utf8'));
      buffered = buffered.subarray(end + 1);
      if (msg.id && waiting.has(msg.id)) {
        const w = waiting.get(msg.id);
        waiting.delete(msg.id);
        if (msg.error) w.reject(new Error(JSON.stringify(msg.error)));
        else w.resolve(msg.result);
      } else {
        listeners.forEach((l) => l(msg));
      }
    }
  });
  const finish = (code) => {
    server.close();
    const cleanUp = () => {
      // Chromium's helpers (GPU, crash handler) may still be writing the profile when the browser
      // itself has exited: retried (ENOTEMPTY is one of the errors rmSync retries), and a profile
      // that still cannot go is reported, not taken for the page's failure.
      try {
        fs.rmSync(profile, { recursive: true, force: true, maxRetries: 20, retryDelay: 50 });
      } catch (e) {
        console.error('page_check: could not remove ' + profile + ': ' + e.message);
      }
      process.exit(code);
    };
    if (browser.exitCode !== null || browser.signalCode !== null) cleanUp();
    browser.on('exit', cleanUp);  // the profile is removed once the browser stopped writing it
    browser.kill();
  };
  browser.on('error', (e) => { console.error('cannot start ' + chromium + ': ' + e.message); finish(1); });

  async function open(query) {
    const { targetId } = await send('Target.createTarget', { url: 'about:blank' });
    const { sessionId } = await send('Target.attachToTarget', { targetId, flatten: true });
    const report = { query, lines: [], exceptions: [], done: false };
    let resolveDone;
    const done = new Promise((r) => { resolveDone = r; });
    const listener = (msg) => {
      if (msg.sessionId !== sessionId) return;
      if (msg.method === 'Runtime.consoleAPICalled') {
        const text = msg.params.args.map((a) => (a.value !== undefined ? String(a.value) : a.description || '')).join(' ');
        report.lines.push(text);
        if (text.startsWith('dynlab canvas:') || text.startsWith('dynlab results.json:') || text.startsWith('dynlab bench:')) {
          report.done = true;
          resolveDone();
        }
      } else if (msg.method === 'Runtime.exceptionThrown') {
        const d = msg.params.exceptionDetails;
        report.exceptions.push((d.exception && d.exception.description) || d.text);
      }
    };
    listeners.push(listener);
    await send('Runtime.enable', {}, sessionId);
    await send('Page.navigate', { url: 'http://127.0.0.1:' + port + '/index.html' + query }, sessionId);
    await Promise.race([done, new Promise((r) => setTimeout(r, timeoutMs))]);
    listeners.splice(listeners.indexOf(listener), 1);
    if (shots) {
      await new Promise((r) => setTimeout(r, 1000));  // a few more frames: the panel laid out
      const { data } = await send('Page.captureScreenshot', { format: 'png' }, sessionId);
      fs.writeFileSync(path.join(shots, 'page-' + (queries.indexOf(query) + 1) + '.png'), Buffer.from(data, 'base64'));
    }
    await send('Target.closeTarget', { targetId });
    console.log(JSON.stringify(report));
  }

  (async () => {
    for (const q of queries) await open(q);
    finish(0);
  })().catch((e) => { console.error('page_check: ' + e.message); finish(1); });
}

server.listen(0, '127.0.0.1', () => main(server.address().port));
