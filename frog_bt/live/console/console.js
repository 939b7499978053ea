// The console page's script (served as /console.js; the page's policy allows no other).
// Everything the executive, the robot or the site says is inserted as text (textContent,
// DOM and SVG nodes), never as markup: a fault's message is shown, never run.
// Words: the page's English is the catalogs' msgid; /api/words?lang= gives them in the
// chosen language (remembered in localStorage), t() fills in {fields}.
"use strict";
const $ = (id) => document.getElementById(id);
const SVG = "http://www.w3.org/2000/svg";
const HEALTH = {connected:"ok", acking:"ok", wall:"ok", "/clock":"ok", connecting:"wait", reconnecting:"wait",
  "not heard":"wait", silent:"bad", "waiting for /clock":"bad", closed:"off"};
const LINK_WORDS = () => ({connected: t("connected"), reconnecting: t("reconnecting"), connecting: t("connecting"),
  closed: t("closed"), acking: t("answering"), "not heard": t("not heard yet"), silent: t("silent"),
  wall: t("wall clock"), "/clock": t("simulated clock"), "waiting for /clock": t("waiting for the clock")});
const LINK_NAMES = () => ({rosbridge: t("The robot"), frontend: t("Screen and sound"), clock: t("Clock")});
const CONFIRM_FOR = 6000;  // ms a first tap waits for the confirming one
const ANSWER_FOR = 15000;  // ms a "done" answer stays in view (a refusal stays until tapped)
let site = null, latest = null, words = {}, lang = "en", armed = null;
let connected = false, sending = false;  // buttons work only when connected, one command at a time

function t(msgid, args) {  // msgid in the chosen language, {fields} filled in
  let text = words[msgid] || msgid;
  for (const [k, v] of Object.entries(args || {})) text = text.split(`{${k}}`).join(String(v));
  return text;
}

function tw(wire) {  // a sentence from the server: [msgid, {field: value or [msgid, {...}]}]
  if (!wire) return "";
  const args = {};
  for (const [k, v] of Object.entries(wire[1] || {})) args[k] = Array.isArray(v) ? tw(v) : v;
  return t(wire[0], args);
}

function el(tag, attrs, ...children) {  // an HTML element; children are nodes or text
  const e = document.createElement(tag);
  for (const [k, v] of Object.entries(attrs || {})) e.setAttribute(k, String(v));
  e.append(...children.map((c) => (c instanceof Node ? c : String(c))));
  return e;
}

function svg(tag, attrs, ...children) {  // an SVG element; text children become text nodes
  const e = document.createElementNS(SVG, tag);
  for (const [k, v] of Object.entries(attrs || {})) e.setAttribute(k, String(v));
  e.append(...children.map((c) => (c instanceof Node ? c : String(c))));
  return e;
}

function duration(s) {
  if (s === null || s === undefined) return "–";
  s = Math.max(0, Math.round(s));
  return s < 90 ? t("{s} s", {s}) : t("{m} min {s} s", {m: Math.floor(s / 60), s: s % 60});
}

// ------------------------------------------------------------------ words

async function loadWords(wanted) {
  const r = await fetch(`/api/words?lang=${encodeURIComponent(wanted)}`, {headers: authHeaders()});
  if (!r.ok) return;
  const body = await r.json();
  words = body.words; lang = body.language;
  document.documentElement.lang = lang;
  $("lang").value = lang;
  document.querySelectorAll("[data-w]").forEach((e) => {
    if (!e.dataset.msgid) e.dataset.msgid = e.textContent.trim();
    e.textContent = t(e.dataset.msgid);
  });
  document.title = t("FROG – tour robot");
  $("map").setAttribute("aria-label", t("Map"));
  drawLegend();
  if (latest) render(latest);
}

$("lang").addEventListener("change", () => {
  localStorage.setItem("frog-lang", $("lang").value);
  loadWords($("lang").value);
});

// ------------------------------------------------------------------ the staff code

const DEVICE = "frog-device";  // a paired phone's own key (pair.js keeps it), used before any code

function token(why, steering) {  // steering: the code is asked for a command (reads may need none)
  const key = localStorage.getItem(DEVICE);
  if (key) return key;
  let code = sessionStorage.getItem("frog-token");
  if (!code) {
    code = prompt(why || t("Staff code (asked once per session):"));
    if (code) { sessionStorage.setItem("frog-token", code); $("login").hidden = true; }
    else showLogin(steering ? t("Without the staff code the robot cannot be steered from here.")
      : t("Without the staff code the robot can be neither shown nor steered from here."));
  }
  return code;
}

function authHeaders() {  // the key or the token travels in a header, never in a URL
  const code = localStorage.getItem(DEVICE) || sessionStorage.getItem("frog-token");
  return code ? {"Authorization": "Bearer " + code} : {};
}

function showLogin(why) {
  $("login-why").textContent = why;
  $("login").hidden = false;
}

function refused(steering) {  // a wrong code: say so, forget it, ask again
  if (localStorage.getItem(DEVICE)) {  // this phone was unpaired: its key no longer works
    localStorage.removeItem(DEVICE); localStorage.removeItem(DEVICE + "-name");
    showDevice();
    showLogin(t("This phone is no longer paired: enter the staff code, or pair it again."));
    return null;
  }
  sessionStorage.removeItem("frog-token");
  return token(t("That staff code was not accepted. Enter it again:"), steering);
}

$("login-again").addEventListener("click", () => { if (token()) start(); });

function showDevice() {  // a paired phone says whose it is
  const name = localStorage.getItem(DEVICE) && localStorage.getItem(DEVICE + "-name");
  $("device").hidden = !name;
  $("device").textContent = name ? t("This phone: {name}", {name}) : "";
}

// ------------------------------------------------------------------ commands

let answerTimer = null;
function answer(ok, text) {  // a banner at the foot of the screen, in view wherever the finger is
  clearTimeout(answerTimer);
  $("answer").className = ok ? "ok" : "bad";
  $("answer").textContent = text;
  if (ok && text !== "…") answerTimer = setTimeout(() => { $("answer").textContent = ""; }, ANSWER_FOR);
}
$("answer").addEventListener("click", () => { $("answer").textContent = ""; });

function enableButtons() {  // what the robot can do now, when connected and nothing is on its way
  const can = connected && !sending && latest ? latest.can || [] : [];
  document.querySelectorAll("button[data-command]").forEach((b) => {
    b.disabled = !can.includes(b.dataset.command);
    if (b.disabled && armed && armed.button === b) disarm();
  });
  document.querySelectorAll("button[data-ack]").forEach((b) => { b.disabled = !connected || sending; });
  $("hand-over").disabled = !connected || sending;
  $("pair-go").disabled = !connected || sending;
}

async function post(path, payload, done) {  // a command (or a handover) with the staff code
  let code = token(null, true);
  if (!code) return;
  sending = true; enableButtons();
  answer(true, "…");
  try {
    for (let tries = 0; tries < 2; tries++) {
      const r = await fetch(`${path}?lang=${encodeURIComponent(lang)}`, {method: "POST",
        headers: {"Content-Type": "application/json", "Authorization": "Bearer " + code},
        body: JSON.stringify(payload)});
      if (r.status === 401) { code = refused(true); if (!code) { answer(false, t("Not done: no staff code.")); return; } continue; }
      const body = await r.json();
      if (r.status === 429) { answer(false, t("Not done: too many tries. Wait a moment and try again.")); return; }
      answer(body.ok, body.ok ? t("Done: {what}", {what: done(body)}) : t("Not done: {why}", {why: body.reason}));
      return;
    }
  } catch (e) {
    answer(false, t("Not done: no answer from the robot's computer"));
  } finally {
    sending = false; enableButtons();
  }
}

function send(command, extra) {
  return post("/api/command", Object.assign({command}, extra || {}), (body) => body.did);
}

$("hand-over").addEventListener("click", () => post("/api/handover", {},
  (body) => { renderHandover(body.handover); return t("the handover is composed and sent"); }));

$("pair").addEventListener("submit", (e) => {  // a QR code of a one-time link for a new phone
  e.preventDefault();
  const name = $("pair-name").value.trim();
  if (!name) { answer(false, t("Not done: {why}", {why: t("a device needs a name, such as Lucía's phone")})); return; }
  post("/api/pair", {name}, (body) => {
    drawQR(body.qr);
    $("pair-link").textContent = body.link;
    $("pair-shown").hidden = false;
    return t("scan this code with the phone within {m} min; it works once", {m: Math.round(body.expires_in / 60)});
  });
});

function drawQR(qr) {  // the path data of segno's SVG, set as an attribute: no markup parsed
  const n = qr.size;
  $("qr").setAttribute("viewBox", `0 0 ${n} ${n}`);
  $("qr").replaceChildren(svg("rect", {width: n, height: n, fill: "#fff"}),
    svg("path", {d: qr.path, stroke: "#000", "stroke-width": 1, fill: "none"}));
}

function renderHandover(h) {  // the last handover, in the site's language, as text
  $("handover-title").textContent = h ? h.title : t("No handover yet.");
  $("handover").replaceChildren(...(h ? h.sections.flatMap((s) =>
    [el("h3", {}, s.title), el("ul", {}, ...s.lines.map((l) => el("li", {}, l)))]) : []));
}

function disarm() {
  if (!armed) return;
  armed.button.classList.remove("confirm");
  armed.button.textContent = t(armed.button.dataset.msgid);
  clearTimeout(armed.timer); armed = null;
}

document.querySelectorAll("button[data-command]").forEach((b) => b.addEventListener("click", () => {
  if (b.dataset.confirm && !(armed && armed.button === b)) {  // one more tap to be sure
    disarm();
    b.classList.add("confirm");
    b.textContent = t("Tap again to confirm: {what}", {what: t(b.dataset.msgid)});
    armed = {button: b, timer: setTimeout(disarm, CONFIRM_FOR)};
    return;
  }
  disarm();
  send(b.dataset.command);
}));

async function read(path) {  // reads need the token only when the console is not on loopback
  let r = await fetch(path, {headers: authHeaders()});
  if (r.status === 401) {
    if (!(sessionStorage.getItem("frog-token") ? refused() : token())) return null;
    r = await fetch(path, {headers: authHeaders()});
    if (r.status === 401) { refused(); return null; }
  }
  return r.ok ? r.json() : null;
}

$("show-tree").addEventListener("click", async () => {
  const box = $("tree");
  if (!box.hidden) { box.hidden = true; $("show-tree").textContent = t("Show the whole tree"); return; }
  const root = await read("/api/tree");
  if (!root) return;
  const lines = [];
  (function walk(n, depth) {
    lines.push(`${"  ".repeat(depth)}${n.status === "RUNNING" ? "▶" : n.status === "SUCCESS" ? "✓" : n.status === "FAILURE" ? "✗" : "·"} ${n.name}`);
    n.children.forEach((c) => walk(c, depth + 1));
  })(root, 0);
  box.textContent = lines.join("\n"); box.hidden = false; $("show-tree").textContent = t("Hide the tree");
});

// ------------------------------------------------------------------ the map

const COLOURS = {stop: "#1f2937", dock: "#14532d", recruit: "#7c3aed", robot: "#2563eb", person: "#f59e0b"};

function drawLegend() {
  const item = (colour, text) => { const sw = el("span", {}); sw.style.background = colour; return el("li", {}, sw, text); };
  $("legend").replaceChildren(item(COLOURS.robot, t("the robot")), item(COLOURS.person, t("a person")),
    item(COLOURS.stop, t("a stop of the tour")), item(COLOURS.dock, t("the charger")),
    item(COLOURS.recruit, t("where it looks for visitors")));
}

function placeLabels(marks, size) {  // labels above their mark, moved below or aside when they would cover another label or mark
  const placed = [];
  const dots = marks.map((m) => ({x: m.x, y: m.y}));
  for (const m of [...marks].sort((a, b) => a.y - b.y)) {
    const w = m.text.length * size * 0.55, h = size * 1.1;
    const free = (c) => !placed.some((p) => Math.abs(p.x - c.x) < (p.w + w) / 2 && Math.abs(p.y - c.y) < h)
      && !dots.some((d) => (d.x !== m.x || d.y !== m.y) && Math.abs(d.x - c.x) < w / 2 + size * .3
        && d.y > c.y - h * .8 && d.y < c.y + size * .4);
    const candidates = [[0, -0.9], [0, 1.6], [w / 2 + size * .5, 0.35], [-w / 2 - size * .5, 0.35], [0, -2.0], [0, 2.7]]
      .map(([dx, dy]) => ({x: m.x + dx, y: m.y + dy * size}));
    const at = candidates.find(free) || candidates[0];
    placed.push({x: at.x, y: at.y, w, text: m.text});
  }
  return placed;
}

function drawMap(s) {
  if (!site) return;
  const pts = [];
  site.pois.forEach((p) => pts.push([p.x, p.y]));
  site.zones.forEach((z) => z.points.forEach((p) => pts.push(p)));
  if (s && s.robot) pts.push([s.robot.x, s.robot.y]);
  const xs = pts.map((p) => p[0]), ys = pts.map((p) => p[1]);
  const minx = Math.min(...xs) - 12, maxx = Math.max(...xs) + 12, miny = Math.min(...ys) - 6, maxy = Math.max(...ys) + 8;
  const w = maxx - minx, h = maxy - miny, k = 100 / w;
  const X = (x) => (x - minx) * k, Y = (y) => (maxy - y) * k;
  const tall = h * k;  // the viewBox's height (it is 100 wide)
  // one unit of marks and text, in viewBox units: labels about 13 px whatever the screen
  const px = Math.min(($("map").clientWidth || 300) / 100, 0.8 * window.innerHeight / tall);
  const u = 13 / 1.5 / px;
  $("map").setAttribute("viewBox", `0 0 100 ${tall.toFixed(2)}`);
  const out = [];
  const points = (ps) => ps.map((p) => X(p[0]).toFixed(2) + "," + Y(p[1]).toFixed(2)).join(" ");
  site.zones.forEach((z) => out.push(svg("polygon", {points: points(z.points),
    fill: z.kind === "volume" ? "#bbf7d0" : "#fbcfe8", "fill-opacity": ".5", stroke: "#9ca3af",
    "stroke-width": u / 10}, svg("title", {}, z.label))));
  site.routes.slice(0, 1).forEach((r) => out.push(svg("polyline", {points: points(r.points), fill: "none",
    stroke: "#a78bfa", "stroke-width": u / 5, "stroke-dasharray": `${u} ${u / 2}`})));
  const colour = (p) => p.label === site.dock ? COLOURS.dock : p.label === site.recruit_at ? COLOURS.recruit : COLOURS.stop;
  const marks = site.pois.map((p) => ({x: X(p.x), y: Y(p.y), text: p.name, colour: colour(p)}));
  marks.forEach((m) => out.push(svg("circle", {cx: m.x, cy: m.y, r: u / 2.5, fill: m.colour})));
  if (s) {
    s.people.forEach((p) => out.push(svg("circle", {cx: X(p[0]), cy: Y(p[1]), r: u * .5, fill: COLOURS.person},
      svg("title", {}, t("a person")))));
    if (s.robot) {
      const a = -s.robot.yaw, cx = X(s.robot.x), cy = Y(s.robot.y);
      out.push(svg("g", {transform: `translate(${cx},${cy}) rotate(${a * 180 / Math.PI}) scale(${u * .6})`, opacity: ".85"},
        svg("circle", {r: 1.2, fill: COLOURS.robot}), svg("path", {d: "M0,-.5 L1.9,0 L0,.5 z", fill: "#fff"}),
        svg("title", {}, t("the robot"))));
    }
  }
  placeLabels(marks, u * 1.5).forEach((l) => {
    out.push(svg("text", {x: Math.min(Math.max(l.x, l.w / 2), 100 - l.w / 2), y: l.y, "font-size": u * 1.5,
      "text-anchor": "middle", "paint-order": "stroke", stroke: "#fff", "stroke-width": u / 3, fill: "#111"}, l.text));
  });
  $("map").replaceChildren(...out);
}

// ------------------------------------------------------------------ the state

function linkRow(name, st, since) {
  const dot = el("span", {class: "dot"});
  dot.style.background = `var(--${HEALTH[st] || "off"})`;
  return [el("dt", {}, dot, LINK_NAMES()[name] || name),
    el("dd", {}, t("{state}, for {time}", {state: LINK_WORDS()[st] || st, time: duration(since)}))];
}

function alertRow(a) {
  const button = el("button", {}, t("Seen"));
  button.dataset.ack = a.id;
  button.addEventListener("click", () => send("ack_alert", {id: a.id}));
  button.disabled = !connected || sending;
  const state = a.state === "cleared" ? "cleared" : "raised";
  return el("div", {class: `alert ${state}`, role: "alert"},
    el("span", {}, el("strong", {}, a.state === "raised" ? t("The robot needs help") : t("Solved"), ":"), " ", a.text),
    button);
}

function holdingRow(a) {
  return el("div", {class: "alert holding"}, el("span", {}, el("strong", {}, t("Still true"), ":"), " ", a.text));
}

function name(code) {  // a stop or a place (the charger) by the name staff know it by
  const poi = site && site.pois.find((p) => p.label === code);
  return (site && site.names && site.names[code]) || (poi && poi.name) || code;
}

function render(s) {
  latest = s;
  $("phase").textContent = tw(s.words.doing);
  $("doing").textContent = tw(s.words.doing);
  $("paused").hidden = !s.paused;
  $("help").hidden = !s.help;
  if (s.help) {
    $("help-what").textContent = tw(s.words.help.what);
    $("help-since").textContent = t("Waiting for {time}.", {time: duration(s.time - s.help.since)});
    $("help-hand").textContent = tw(s.words.help.by_hand);
  }
  $("service").hidden = s.in_service;
  $("stop").textContent = s.stop ? name(s.stop) : s.touring ? t("looking for a visitor") : t("no tour now");
  const first = site && site.stops.length ? name(site.stops[0]) : "–";
  $("next").textContent = s.next_stop ? name(s.next_stop) : s.touring && !s.stop ? first : "–";
  $("atstop").textContent = s.stop ? (s.at_stop_s === null ? t("on the way") : duration(s.at_stop_s)) : "–";
  $("visitor").textContent = s.visitor === null ? "–" : s.introducing ? t("being greeted") : t("on a tour");
  $("battery").textContent = s.battery === null ? "–" : `${Math.round(s.battery)} %`;
  $("meter").style.width = s.engagement === null || s.engagement === undefined ? "0" : `${Math.round((s.engagement + 1) * 50)}%`;
  $("links").replaceChildren(...Object.entries(s.links).flatMap(([n, st]) => linkRow(n, st, s.links_for_s[n])));
  for (const k of ["started", "completed", "aborted"]) $(k).textContent = s.tours[k];
  $("visitors").textContent = s.day.visitors; $("skipped").textContent = s.day.skipped;
  $("last").replaceChildren(...s.day.last.map((l) => el("li", {}, l)));
  $("path").textContent = s.path.join("  ›  ");
  $("log").textContent = s.log.join("\n");
  $("alerts").replaceChildren(...s.alerts.concat(s.cleared || []).map(alertRow));
  $("holding").replaceChildren(...(s.holding || []).map(holdingRow));
  renderHandover(s.handover);
  enableButtons();
  drawMap(s);
}

async function streamURL() {  // off loopback: a one-use ticket, so the token stays out of URLs
  const base = `${location.protocol === "https:" ? "wss" : "ws"}://${location.host}/api/stream`;
  if (!authHeaders().Authorization) return base;
  try {
    const r = await fetch("/api/ticket", {method: "POST", headers: authHeaders()});
    if (r.ok) return `${base}?ticket=${encodeURIComponent((await r.json()).ticket)}`;
  } catch (e) { /* no ticket: try without (on loopback the stream needs none) */ }
  return base;
}

async function connect() {
  const ws = new WebSocket(await streamURL());
  ws.addEventListener("open", () => { $("offline").hidden = true; });
  ws.addEventListener("message", (e) => { connected = true; render(JSON.parse(e.data)); });
  ws.addEventListener("close", () => {
    connected = false; enableButtons();
    $("offline").hidden = false; setTimeout(connect, 2000);
  });
}

let started = false;
async function start() {
  if (started) return;
  const s = await read("/api/site");
  if (!s) return;  // no code, or a wrong one: the page says so and offers to ask again
  started = true; site = s; $("login").hidden = true;
  await loadWords(localStorage.getItem("frog-lang") || site.language || "es");
  showDevice();
  drawMap(latest); connect();
}

window.addEventListener("resize", () => drawMap(latest));
start();
