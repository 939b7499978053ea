// The page a pairing link opens on a phone (served as /pair.js; no inline script). The
// one-time code is in the link's fragment, which the browser never sends to a server; it
// leaves the address bar at once, is claimed once, and the device's own key is kept in
// this browser (localStorage), sent from then on in a header, never in a URL.
"use strict";
const said = document.getElementById("said");

async function claim() {
  const code = location.hash.slice(1);
  history.replaceState(null, "", location.pathname);
  if (!code) { said.textContent = "Este enlace no lleva código. / This link carries no code."; said.className = "bad"; return; }
  try {
    const r = await fetch("/api/pair/claim", {method: "POST",
      headers: {"Content-Type": "application/json"}, body: JSON.stringify({code})});
    const body = await r.json();
    if (!body.ok) { said.textContent = body.reason; said.className = "bad"; return; }
    localStorage.setItem("frog-device", body.key);
    localStorage.setItem("frog-device-name", body.name);
    said.textContent = body.said;
    document.getElementById("open").textContent = body.open;
    document.getElementById("open").hidden = false;
  } catch (e) {
    said.textContent = "Sin respuesta del ordenador del robot. / No answer from the robot's computer.";
    said.className = "bad";
  }
}
claim();
