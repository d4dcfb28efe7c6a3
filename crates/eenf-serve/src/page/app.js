// The page's script: upload, poll, show. No library, nothing fetched from elsewhere.
"use strict";

const token = new URLSearchParams(location.search).get("token") || "";
const $ = (id) => document.getElementById(id);
let generation = 0; // a new upload stops the polling of the one before

function api(path, init = {}) {
  const headers = Object.assign({}, init.headers || {}, { "X-Eenf-Token": token });
  return fetch(path, Object.assign({}, init, { headers }));
}

function el(tag, text, cls) {
  const e = document.createElement(tag);
  if (text !== undefined) e.textContent = text;
  if (cls) e.className = cls;
  return e;
}

function show(id, on) { $(id).hidden = !on; }

function failed(message) {
  show("progress", false);
  $("error").textContent = message;
  show("error", true);
}

async function loadConfig() {
  try {
    const r = await api("/api/config");
    const c = await r.json();
    $("stores").textContent = c.stores.length
      ? `Searched for when it was recorded: ${c.stores.join(", ")}`
      : "No reference store was given (eenf serve --store DIR): the time of recording is not searched.";
  } catch (e) {
    $("stores").textContent = "";
  }
}

async function analyse(file) {
  const gen = ++generation;
  show("error", false);
  show("results", false);
  show("progress", true);
  $("status").textContent = `Uploading ${file.name} …`;
  $("bar").removeAttribute("value");
  const options = {};
  if ($("nominal").value) options.nominal = $("nominal").value;
  if ($("verify").value.trim()) options.verify = $("verify").value.trim();
  const form = new FormData();
  form.append("options", JSON.stringify(options));
  form.append("file", file, file.name);
  let r, j;
  try {
    r = await api("/api/analyses", { method: "POST", body: form });
    j = await r.json();
  } catch (e) {
    return failed(`${file.name}: the upload failed (${e})`);
  }
  if (!r.ok) return failed(j.error || `${file.name}: HTTP ${r.status}`);
  poll(j.id, gen);
}

async function poll(id, gen) {
  for (;;) {
    if (gen !== generation) return;
    let j;
    try {
      j = await (await api(`/api/analyses/${id}`)).json();
    } catch (e) {
      return failed(`the server stopped answering (${e})`);
    }
    if (gen !== generation) return;
    if (j.state === "done") return render(id, j);
    if (j.state === "failed") return failed(j.error);
    const p = j.progress || {};
    $("status").textContent = j.state === "queued"
      ? `${j.name}: waiting for a free core …`
      : `${j.name}: ${p.what || "analysing"} …`;
    if (p.total) { $("bar").max = p.total; $("bar").value = p.done; } else { $("bar").removeAttribute("value"); }
    await new Promise((res) => setTimeout(res, 400));
  }
}

function svgInto(target, svg) {
  target.replaceChildren();
  if (!svg) return;
  // the server's own figure (text in it is escaped by the SVG writer)
  const doc = new DOMParser().parseFromString(svg, "image/svg+xml");
  target.appendChild(document.importNode(doc.documentElement, true));
}

function render(id, job) {
  const a = job.result;
  show("progress", false);
  $("verdict").textContent = a.verdict;
  const warnings = $("warnings");
  const notes = (a.line ? [el("li", a.line)] : []).concat(
    (a.notices || []).map((w) => el("li", w, "warning")));
  warnings.replaceChildren(...notes);
  svgInto($("trace"), a.figures.trace);
  svgInto($("flicker-map"), a.figures.flicker_map);
  show("flicker", Boolean(a.figures.flicker_map));

  const match = $("match");
  match.replaceChildren();
  if (!a.matches.length) match.appendChild(el("p", "No reference store was searched."));
  a.match_verdicts.forEach((v) => match.appendChild(el("p", v, "verdict")));
  for (const m of a.matches) {
    if (!m.result) continue;
    const table = el("table");
    const head = el("tr");
    ["rank", "start (UTC)", "grid", "CC", "MAE mHz", "p"].forEach((h) => head.appendChild(el("th", h)));
    table.appendChild(head);
    m.result.candidates.forEach((c, i) => {
      const row = el("tr", undefined, c.match ? "match" : "");
      const when = el("time", c.start_utc || c.start);
      if (c.start_utc) when.setAttribute("datetime", c.start_utc);
      const cell = el("td");
      cell.appendChild(when);
      row.append(el("td", String(i + 1)), cell, el("td", c.reference),
        el("td", c.cc.toFixed(4)), el("td", (c.mae_hz * 1e3).toFixed(3)), el("td", c.p_value.toExponential(1)));
      table.appendChild(row);
    });
    match.appendChild(table);
    if (m.result.verify) {
      const v = m.result.verify;
      match.appendChild(el("p", `Claimed start ${v.time}: rank ${v.rank}, CC ${v.cc.toFixed(4)}, p ${v.p_value.toExponential(1)}` +
        (v.consistent ? " — consistent with the recording" : " — not the best fit")));
    }
  }
  const fig = el("div", undefined, "figure");
  svgInto(fig, a.figures.matched);
  match.appendChild(fig);

  const edits = $("edits");
  edits.replaceChildren(el("p", a.edits_verdict, "verdict"));
  for (const x of (a.edits.edits || [])) {
    edits.appendChild(el("p", `${x.time_s.toFixed(1)} s: ${x.kind.replaceAll("_", " ")}, p ${x.p_value.toExponential(1)}. ${x.reading}`));
  }
  const efig = el("div", undefined, "figure");
  svgInto(efig, a.figures.edits);
  edits.appendChild(efig);

  $("about").textContent = JSON.stringify(a.about, null, 2);
  const link = $("report");
  link.href = `/api/analyses/${id}/report?token=${encodeURIComponent(token)}`;
  link.setAttribute("download", "");
  show("results", true);
}

$("file").addEventListener("change", (ev) => {
  const f = ev.target.files[0];
  if (f) analyse(f);
});
const drop = $("drop");
drop.addEventListener("dragover", (ev) => { ev.preventDefault(); drop.classList.add("over"); });
drop.addEventListener("dragleave", () => drop.classList.remove("over"));
drop.addEventListener("drop", (ev) => {
  ev.preventDefault();
  drop.classList.remove("over");
  const f = ev.dataTransfer.files[0];
  if (f) analyse(f);
});
loadConfig();
