// A legend as the lines of an exported PNG: the entries shown (hidden estimators left out),
// each wrapped to the image's width so that nothing is cut at the right edge.
// Pure (no DOM): web/test/claims.test.mjs runs it under Node.

/**
 * items: [{text, hidden}], `measure(text)` the drawn width of a text, `width` the room for a
 * line. Returns [{item: index, text, first (the item's first line: it carries the swatch)}].
 */
export function legendLines(items, { measure, width }) {
  const out = [];
  items.forEach((it, index) => {
    if (it.hidden) return;
    const words = String(it.text).replace(/\s+/g, ' ').trim().split(' ');
    let line = '';
    let first = true;
    const push = () => {
      out.push({ item: index, text: line, first });
      first = false;
      line = '';
    };
    for (const w of words) {
      const candidate = line ? `${line} ${w}` : w;
      if (line && measure(candidate) > width) {
        push();
        line = w;
      } else {
        line = candidate;
      }
      // A single word wider than the line (a long number run): cut it by characters.
      while (measure(line) > width && line.length > 1) {
        let k = line.length - 1;
        while (k > 1 && measure(line.slice(0, k)) > width) k--;
        const rest = line.slice(k);
        line = line.slice(0, k);
        push();
        line = rest;
      }
    }
    if (line || first) push();
  });
  return out;
}
