// Where the names of a plot's guide lines go (the time plot's t^-1/2 and t^-1): each label sits
// just above its line's end, and labels that would overlap are moved apart vertically, the
// upper one up, all kept inside the plot. Pure: no canvas (web/test/guide_labels.test.mjs).

/**
 * Label boxes: `labels` [{x, y, width}] with x the right edge and y the baseline each label
 * wants (canvas pixels, y down), `height` a label's height, `gap` the room kept between two
 * labels, [top, bottom] the plot's vertical extent. Returns the baselines, in the order given:
 * two labels overlap when their x extents [x - width, x] meet and their baselines are less than
 * height + gap apart; then the upper one (smaller y) moves up. A label that would leave the top
 * goes below the others instead, and no baseline is above top + height or below bottom.
 */
export function placeGuideLabels(labels, { height, gap = 2, top, bottom }) {
  const clamp = (y) => Math.min(bottom, Math.max(top + height, y));
  const order = labels.map((l, i) => ({ ...l, i, y: clamp(l.y) })).sort((a, b) => b.y - a.y || a.i - b.i);
  const placed = [];
  const meets = (a, b) => a.x - a.width < b.x && b.x - b.width < a.x;
  const clash = (l, y) => placed.find((p) => meets(p, l) && Math.abs(p.y - y) < height + gap);
  for (const l of order) {
    let y = l.y;
    // up, past every label it meets (the lowest labels were placed first)
    for (let hit = clash(l, y); hit; hit = clash(l, y)) y = hit.y - height - gap;
    if (y < top + height) {
      // no room above: under the lowest label it meets, at the bottom at most
      y = l.y;
      for (let hit = clash(l, y); hit; hit = clash(l, y)) y = hit.y + height + gap;
      y = Math.min(bottom, y);
    }
    placed.push({ ...l, y });
  }
  const out = new Array(labels.length);
  for (const p of placed) out[p.i] = p.y;
  return out;
}
