// The console page's script (served as /console.js; the page's policy allows no other).
// Everything the executive, the robot or the site says is inserted as text (textContent,
// DOM and SVG nodes), never as markup: a fault's message is shown, never run.
"use strict";
const $ = (id) => document.getElementById(id);
const SVG = "http://www.w3.org/2000/svg";
const WORDS = {connected:"connected", reconnecting:"reconnecting", connecting:"connecting", closed:"closed",
  acking:"answering", "not heard":"not heard yet", silent:"silent", wall:"wall clock", "/clock":"simulated clock",
  "waiting for /clock":"waiting for the clock"};
const HEALTH = {connected:"ok", acking:"ok", wall:"ok", "/clock":"ok", connecting:"wait", reconnecting:"wait",
  "not heard":"wait", silent:"bad", "waiting for /clock":"bad", closed:"off"};
const NAMES = {rosbridge:"Robot (rosbridge)", frontend:"Screen and sound (front end)", clock:"Clock"};
let site = null, latest = null;

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
  return s < 90 ? `${s} s` : `${Math.floor(s / 60)} min ${s % 60} s`;
}

function token() {
  let t = sessionStorage.getItem("frog-token");
  if (!t) { t = prompt("Staff token (asked once per session):"); if (t) sessionStorage.setItem("frog-token", t); }
  return t;
}

function authHeaders() {  // the token travels in a header, never in a URL
  const t = sessionStorage.getItem("frog-token");
  return t ? {"Authorization": "Bearer " + t} : {};
}

async function send(command, extra) {
  const t = token();
  if (!t) return;
  $("answer").textContent = "…";
  try {
    const r = await fetch("/api/command", {method:"POST", headers:{"Content-Type":"application/json",
      "Authorization":"Bearer " + t}, body: JSON.stringify(Object.assign({command}, extra || {}))});
    const body = await r.json();
    if (r.status === 401) sessionStorage.removeItem("frog-token");
    $("answer").className = body.ok ? "ok" : "bad";
    $("answer").textContent = body.ok ? `Done: ${body.did}` : `Not done: ${body.reason}`;
  } catch (e) {
    $("answer").className = "bad"; $("answer").textContent = "Not done: no answer from the robot's computer";
  }
}

document.querySelectorAll("button[data-command]").forEach((b) =>
  b.addEventListener("click", () => send(b.dataset.command)));

async function read(path) {  // reads need the token only when the console is not on loopback
  let r = await fetch(path, {headers: authHeaders()});
  if (r.status === 401) { sessionStorage.removeItem("frog-token"); token(); r = await fetch(path, {headers: authHeaders()}); }
  return r.json();
}

$("show-tree").addEventListener("click", async () => {
  const box = $("tree");
  if (!box.hidden) { box.hidden = true; $("show-tree").textContent = "Show the whole tree"; return; }
  const lines = [];
  (function walk(n, depth) {
    lines.push(`${"  ".repeat(depth)}${n.status === "RUNNING" ? "▶" : n.status === "SUCCESS" ? "✓" : n.status === "FAILURE" ? "✗" : "·"} ${n.name}`);
    n.children.forEach((c) => walk(c, depth + 1));
  })(await read("/api/tree"), 0);
  box.textContent = lines.join("\n"); box.hidden = false; $("show-tree").textContent = "Hide the tree";
});

function drawMap(s) {
  if (!site) return;
  const pts = [];
  site.pois.forEach((p) => pts.push([p.x, p.y]));
  site.zones.forEach((z) => z.points.forEach((p) => pts.push(p)));
  if (s && s.robot) pts.push([s.robot.x, s.robot.y]);
  const xs = pts.map((p) => p[0]), ys = pts.map((p) => p[1]);
  const minx = Math.min(...xs) - 5, maxx = Math.max(...xs) + 5, miny = Math.min(...ys) - 5, maxy = Math.max(...ys) + 5;
  const w = maxx - minx, h = maxy - miny, k = 100 / w;
  const X = (x) => ((x - minx) * k).toFixed(2), Y = (y) => ((maxy - y) * k).toFixed(2);
  const u = Math.max(100, h * k) / 60;  // one unit of marks and text, whatever the site's shape
  const map = $("map");
  map.setAttribute("viewBox", `0 0 100 ${(h * k).toFixed(2)}`);
  const out = [];
  const points = (ps) => ps.map((p) => X(p[0]) + "," + Y(p[1])).join(" ");
  site.zones.forEach((z) => out.push(svg("polygon", {points: points(z.points),
    fill: z.kind === "volume" ? "#bbf7d0" : "#fbcfe8", "fill-opacity": ".6", stroke: "#9ca3af",
    "stroke-width": u / 8}, svg("title", {}, z.label))));
  site.routes.slice(0, 1).forEach((r) => out.push(svg("polyline", {points: points(r.points), fill: "none",
    stroke: "#a78bfa", "stroke-width": u / 4, "stroke-dasharray": `${u} ${u / 2}`})));
  site.pois.forEach((p) => {
    out.push(svg("circle", {cx: X(p.x), cy: Y(p.y), r: u / 2, fill: "#1f2937"}));
    out.push(svg("text", {x: X(p.x), y: Y(p.y) - u, "font-size": 1.4 * u, "text-anchor": "middle"}, p.label));
  });
  if (s) {
    s.people.forEach((p) => out.push(svg("circle", {cx: X(p[0]), cy: Y(p[1]), r: u * .7, fill: "#f59e0b"},
      svg("title", {}, "a person"))));
    if (s.robot) {
      const a = -s.robot.yaw, cx = +X(s.robot.x), cy = +Y(s.robot.y);
      out.push(svg("g", {transform: `translate(${cx},${cy}) rotate(${a * 180 / Math.PI}) scale(${u})`},
        svg("circle", {r: 1.2, fill: "#2563eb"}), svg("path", {d: "M0,-.5 L1.9,0 L0,.5 z", fill: "#fff"}),
        svg("title", {}, "the robot")));
    }
  }
  map.replaceChildren(...out);
}

function linkRow(name, st, since) {
  const dot = el("span", {class: "dot"});
  dot.style.background = `var(--${HEALTH[st] || "off"})`;
  return el("div", {class: "link"}, el("span", {}, dot, NAMES[name] || name),
    el("span", {}, `${WORDS[st] || st}, ${duration(since)}`));
}

function alertRow(a) {
  const button = el("button", {}, "Acknowledge");
  button.dataset.ack = a.id;
  button.addEventListener("click", () => send("ack_alert", {id: a.id}));
  const state = a.state === "cleared" ? "cleared" : "raised";
  return el("div", {class: `alert ${state}`},
    el("span", {}, el("strong", {}, a.state === "raised" ? "The robot needs help" : "Solved", ":"), " ", a.text),
    button);
}

function render(s) {
  latest = s;
  $("phase").textContent = s.phase;
  $("paused").hidden = !s.paused;
  $("help").hidden = !s.help;
  if (s.help) {
    $("help-what").textContent = s.help.what;
    $("help-since").textContent = `Waiting for ${duration(s.time - s.help.since)}.`;
    $("help-hand").textContent = s.help.by_hand || "a person did the step";
  }
  $("service").hidden = s.in_service;
  $("stop").textContent = s.stop ? (s.waypoint && s.waypoint !== s.stop ? `${s.stop} (${s.waypoint})` : s.stop) : "– (no tour)";
  $("next").textContent = s.next_stop || "–";
  $("atstop").textContent = duration(s.at_stop_s);
  $("visitor").textContent = s.visitor === null ? "–" : `person ${s.visitor}`;
  $("battery").textContent = s.battery === null ? "–" : `${Math.round(s.battery)}%`;
  $("meter").style.width = s.engagement === null || s.engagement === undefined ? "0" : `${Math.round((s.engagement + 1) * 50)}%`;
  $("links").replaceChildren(...Object.entries(s.links).map(([name, st]) => linkRow(name, st, s.links_for_s[name])));
  for (const k of ["started", "completed", "aborted"]) $(k).textContent = s.tours[k];
  $("visitors").textContent = s.day.visitors; $("skipped").textContent = s.day.skipped;
  $("last").replaceChildren(...s.day.last.map((l) => el("li", {}, l)));
  $("path").textContent = s.path.join("  ›  ");
  $("log").textContent = s.log.join("\n");
  $("alerts").replaceChildren(...s.alerts.map(alertRow));
  drawMap(s);
}

async function streamURL() {  // off loopback: a one-use ticket, so the token stays out of URLs
  const base = `${location.protocol === "https:" ? "wss" : "ws"}://${location.host}/api/stream`;
  const t = sessionStorage.getItem("frog-token");
  if (!t) return base;
  try {
    const r = await fetch("/api/ticket", {method: "POST", headers: authHeaders()});
    if (r.ok) return `${base}?ticket=${encodeURIComponent((await r.json()).ticket)}`;
  } catch (e) { /* no ticket: try without (on loopback the stream needs none) */ }
  return base;
}

async function connect() {
  const ws = new WebSocket(await streamURL());
  ws.addEventListener("open", () => { $("offline").hidden = true; });
  ws.addEventListener("message", (e) => render(JSON.parse(e.data)));
  ws.addEventListener("close", () => { $("offline").hidden = false; setTimeout(connect, 2000); });
}

read("/api/site").then((s) => { site = s; drawMap(latest); connect(); });
