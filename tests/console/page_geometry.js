// What a reader sees of a page, from the page's own geometry: every piece of text shown (HTML text, line by line,
// and SVG <text>), clipped by the scrolling or hidden-overflow boxes around it; the pairs of pieces that overlap;
// and where the element named by arguments[0] (if any) lies in the viewport.
"use strict";
const TOLERANCE = 1;  // px of overlap both ways that a reader does not see (antialiasing, rounding)

function shown(element) {
  for (let e = element; e && e.nodeType === 1; e = e.parentElement) {
    const style = getComputedStyle(e);
    if (style.display === "none" || style.visibility === "hidden" || style.opacity === "0") return false;
  }
  return true;
}

function clipped(element, rect) {
  let { left, top, right, bottom } = rect;
  for (let a = element.parentElement; a && a !== document.documentElement; a = a.parentElement) {
    const style = getComputedStyle(a);
    const isSvgChild = a instanceof SVGElement && a.tagName.toLowerCase() !== "svg";
    if (!isSvgChild && (style.overflowX !== "visible" || style.overflowY !== "visible")) {
      const box = a.getBoundingClientRect();
      left = Math.max(left, box.left); top = Math.max(top, box.top);
      right = Math.min(right, box.right); bottom = Math.min(bottom, box.bottom);
    }
  }
  return { left, top, right, bottom };
}

const pieces = [];
function add(node, text, element, rect) {
  if (rect.width < 1 || rect.height < 1) return;
  const c = clipped(element, rect);
  if (c.right - c.left >= 1 && c.bottom - c.top >= 1) pieces.push({ node, text: text.slice(0, 60), ...c });
}

const walker = document.createTreeWalker(document.body, NodeFilter.SHOW_TEXT);
for (let node = walker.nextNode(); node; node = walker.nextNode()) {
  const text = node.textContent.trim();
  const parent = node.parentElement;
  if (!text || !parent || parent.closest("svg, select, script, style, template") || !shown(parent)) continue;
  const range = document.createRange();
  range.selectNodeContents(node);
  for (const rect of range.getClientRects()) add(node, text, parent, rect);
}
for (const element of document.querySelectorAll("svg text")) {
  const text = element.textContent.trim();
  if (text && shown(element)) add(element, text, element, element.getBoundingClientRect());
}

pieces.sort((a, b) => a.top - b.top);
const overlaps = [];
for (let i = 0; i < pieces.length; i++) {
  const a = pieces[i];
  for (let j = i + 1; j < pieces.length && pieces[j].top < a.bottom - TOLERANCE; j++) {
    const b = pieces[j];
    if (a.node === b.node) continue;
    const width = Math.min(a.right, b.right) - Math.max(a.left, b.left);
    const height = Math.min(a.bottom, b.bottom) - Math.max(a.top, b.top);
    if (width > TOLERANCE && height > TOLERANCE) overlaps.push([a.text, b.text]);
  }
}

let panel = null;
const named = arguments[0] ? document.getElementById(arguments[0]) : null;
if (named) {
  const r = named.getBoundingClientRect();
  panel = { top: r.top, bottom: r.bottom, left: r.left, right: r.right, width: innerWidth, height: innerHeight };
}
return { texts: pieces.length, overlaps: overlaps.slice(0, 20), panel,
         scrollable: document.documentElement.scrollHeight > innerHeight + 1 };
