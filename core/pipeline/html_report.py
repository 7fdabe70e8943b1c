"""One HTML page a person opens: a summary, a sortable and filterable table, each row opening its plots.

The page is self-contained (no network: its data, style and script are inline) and written
atomically. Its data is JSON in a script element the page's own script reads; every value
reaches the page as text (textContent), never as markup. A row's details are line plots
(`{"t": [...], "joints": [{"name", "unit", "error": [...], "path", "goal"}]}`, drawn as SVG with
the tolerance band) or bars (`{"bars": [[label, value, unit], ...]}`).
"""

from __future__ import annotations

import json
from collections.abc import Sequence
from pathlib import Path
from typing import Any

from ..bag import atomic_file
from ..errors import InputError

__all__ = ["check_html_path", "write_html"]


def check_html_path(path: Path) -> None:
    """Refuse a report path whose folder does not exist, before any work (as -o's "cannot write", exit 3); return None.

    Raises:
        InputError: The folder does not exist.
    """
    if not path.parent.is_dir():
        raise InputError(f"--html '{path}': cannot write: folder '{path.parent}' does not exist")


def write_html(
    path: Path, title: str, summary: Sequence[tuple[str, str]], columns: Sequence[str], rows: Sequence[Sequence[Any]],
    details: Sequence[dict[str, Any] | None], verdict_column: int,
) -> None:
    """Write the page to `path`: `summary` pairs on top, a table of `rows` under `columns`; return None.

    `details[i]` is what row i opens (None: nothing); `verdict_column` is the column the
    verdict filter reads.

    Raises:
        UsageError, InputError: `path` cannot be an output file, or cannot be written (atomic_file).
    """
    data = {"title": title, "summary": [list(pair) for pair in summary], "columns": list(columns),
            "rows": [list(row) for row in rows], "details": list(details), "verdict": verdict_column}
    # "</" would end the script element early: escaped, JSON still reads it.
    payload = json.dumps(data, allow_nan=False, separators=(",", ":")).replace("</", "<\\/")
    page = _PAGE.replace("@TITLE@", _text(title)).replace("@DATA@", payload)
    with atomic_file(path) as stream:
        stream.write(page.encode("utf-8"))


def _text(value: str) -> str:
    """Return `value` escaped for HTML text."""
    return value.replace("&", "&amp;").replace("<", "&lt;").replace(">", "&gt;")


_PAGE = """<!doctype html>
<html lang="en"><head><meta charset="utf-8"><title>@TITLE@</title>
<style>
body{font:14px/1.4 system-ui,sans-serif;margin:1.5em;color:#222}
h1{font-size:1.3em;margin:0 0 .6em}
table{border-collapse:collapse}
#summary td{padding:2px 12px 2px 0}
#summary td:first-child{color:#555}
.controls{margin:1em 0 .5em}
.controls input{width:24em;padding:3px}
#items th{cursor:pointer;background:#eee;text-align:left;padding:4px 8px;position:sticky;top:0}
#items td{padding:3px 8px;border-top:1px solid #ddd;white-space:nowrap}
#items tr.item:hover{background:#f4f8ff;cursor:pointer}
.bad{color:#b00;font-weight:600}.good{color:#070}
.details td{background:#fafafa}
svg text{font:11px system-ui,sans-serif}
svg.plot{display:block;margin:4px 0}
</style></head>
<body>
<h1 id="title"></h1>
<table id="summary"></table>
<div class="controls"><input id="filter" type="search" placeholder="filter: any text in a row">
<select id="verdict"><option value="">every verdict</option></select> <span id="count"></span></div>
<table id="items"><thead><tr></tr></thead><tbody></tbody></table>
<script type="application/json" id="report">@DATA@</script>
<script>
"use strict";
const data = JSON.parse(document.getElementById("report").textContent);
const SVG = "http://www.w3.org/2000/svg";
document.getElementById("title").textContent = data.title;
for (const [key, value] of data.summary) {
  const tr = document.getElementById("summary").insertRow();
  tr.insertCell().textContent = key;
  tr.insertCell().textContent = value;
}
const head = document.querySelector("#items thead tr");
const body = document.querySelector("#items tbody");
const order = data.rows.map((_, i) => i);
let sortColumn = -1, ascending = true, opened = new Set();
data.columns.forEach((name, c) => {
  const th = document.createElement("th");
  th.textContent = name;
  th.addEventListener("click", () => { ascending = sortColumn === c ? !ascending : true; sortColumn = c; render(); });
  head.appendChild(th);
});
const verdicts = [...new Set(data.rows.map(r => String(r[data.verdict])))].sort();
for (const v of verdicts) {
  const option = document.createElement("option");
  option.value = option.textContent = v;
  document.getElementById("verdict").appendChild(option);
}
document.getElementById("filter").addEventListener("input", render);
document.getElementById("verdict").addEventListener("change", render);
function shown(value) {
  if (value === null || value === undefined) return "";
  if (typeof value === "number") return Number.isInteger(value) ? String(value) : value.toPrecision(4);
  return String(value);
}
function compare(a, b) {
  const x = data.rows[a][sortColumn], y = data.rows[b][sortColumn];
  if (x === y) return a - b;
  if (x === null || x === "") return 1;
  if (y === null || y === "") return -1;
  const result = (typeof x === "number" && typeof y === "number") ? x - y : String(x).localeCompare(String(y));
  return ascending ? result : -result;
}
function render() {
  const text = document.getElementById("filter").value.toLowerCase();
  const verdict = document.getElementById("verdict").value;
  const rows = sortColumn < 0 ? order : [...order].sort(compare);
  body.replaceChildren();
  let count = 0;
  for (const i of rows) {
    const row = data.rows[i];
    if (verdict && String(row[data.verdict]) !== verdict) continue;
    if (text && !row.some(cell => shown(cell).toLowerCase().includes(text))) continue;
    count += 1;
    const tr = body.insertRow();
    tr.className = "item";
    row.forEach((cell, c) => {
      const td = tr.insertCell();
      td.textContent = shown(cell);
      if (c === data.verdict) td.className = /SUCCESS|pass|solved|^True$/i.test(String(cell)) ? "good" : "bad";
    });
    tr.addEventListener("click", () => { opened.has(i) ? opened.delete(i) : opened.add(i); render(); });
    if (opened.has(i)) {
      const details = body.insertRow();
      details.className = "details";
      const td = details.insertCell();
      td.colSpan = data.columns.length;
      td.appendChild(drawDetails(data.details[i]));
    }
  }
  document.getElementById("count").textContent = count + " of " + data.rows.length + " rows";
}
function node(name, attributes, text) {
  const element = document.createElementNS(SVG, name);
  for (const [key, value] of Object.entries(attributes)) element.setAttribute(key, value);
  if (text !== undefined) element.textContent = text;
  return element;
}
function drawDetails(detail) {
  const box = document.createElement("div");
  if (!detail) { box.textContent = "nothing to draw for this row"; return box; }
  if (detail.bars) { box.appendChild(drawBars(detail.bars)); return box; }
  for (const joint of detail.joints) box.appendChild(drawJoint(detail.t, joint));
  return box;
}
function drawJoint(times, joint) {
  const width = 640, height = 130, left = 70, right = 10, top = 18, bottom = 20;
  const svg = node("svg", {width: width, height: height, class: "plot"});
  const pairs = times.map((t, k) => [t, joint.error[k]]).filter(p => p[0] !== null && p[1] !== null);
  const largest = Math.max(1e-12, ...pairs.map(p => Math.abs(p[1])));
  const band = joint.path > 0 && joint.path <= 3 * largest ? joint.path : 0;
  const span = 1.15 * Math.max(largest, band);
  const t0 = pairs.length ? pairs[0][0] : 0, t1 = pairs.length ? pairs[pairs.length - 1][0] : 1;
  const x = t => left + (width - left - right) * (t - t0) / Math.max(t1 - t0, 1e-9);
  const y = e => top + (height - top - bottom) * (1 - (e + span) / (2 * span));
  if (band > 0) svg.appendChild(node("rect", {x: left, y: y(band), width: width - left - right,
    height: y(-band) - y(band), fill: "#2ca02c", "fill-opacity": 0.15}));
  svg.appendChild(node("line", {x1: left, x2: width - right, y1: y(0), y2: y(0), stroke: "#aaa"}));
  const points = pairs.map(p => x(p[0]).toFixed(1) + "," + y(p[1]).toFixed(1)).join(" ");
  svg.appendChild(node("polyline", {points: points, fill: "none", stroke: "#1f77b4", "stroke-width": 1}));
  const tolerance = joint.path > 0 ? "path \\u00b1" + joint.path.toPrecision(3) + (band ? "" : " (off-scale)")
    : "path 0: not checked";
  svg.appendChild(node("text", {x: left, y: 12}, joint.name + ": largest |error| " + largest.toPrecision(3) + " " +
    joint.unit + "; " + tolerance));
  svg.appendChild(node("text", {x: 2, y: y(span / 1.15) + 4}, "+" + (span / 1.15).toPrecision(3)));
  svg.appendChild(node("text", {x: 2, y: y(-span / 1.15) + 4}, "-" + (span / 1.15).toPrecision(3)));
  svg.appendChild(node("text", {x: left, y: height - 4}, t0.toFixed(2) + " s"));
  svg.appendChild(node("text", {x: width - right - 50, y: height - 4}, t1.toFixed(2) + " s"));
  return svg;
}
function drawBars(bars) {
  const width = 640, row = 20, left = 120;
  const svg = node("svg", {width: width, height: row * bars.length + 6, class: "plot"});
  const largest = Math.max(1e-12, ...bars.map(b => b[1] || 0));
  bars.forEach(([label, value, unit], k) => {
    svg.appendChild(node("text", {x: 2, y: row * k + 15}, label));
    svg.appendChild(node("rect", {x: left, y: row * k + 4, height: row - 8,
      width: (width - left - 90) * (value || 0) / largest, fill: "#1f77b4"}));
    const shownValue = value === null ? "-" : value.toPrecision(3) + " " + unit;
    svg.appendChild(node("text", {x: width - 85, y: row * k + 15}, shownValue));
  });
  return svg;
}
render();
</script>
</body></html>
"""
