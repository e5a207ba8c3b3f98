// Building DOM nodes from data: text only, never HTML from data.

/** el('span', {className, title, dataset: {...}, style: 'css'}, ...children): children that
 *  are null, undefined or false are skipped. */
export function el(tag, props = {}, ...children) {
  const e = document.createElement(tag);
  for (const [k, v] of Object.entries(props)) {
    if (k === 'dataset') Object.assign(e.dataset, v);
    else if (k === 'style') e.style.cssText = v;
    else e[k] = v;
  }
  for (const c of children) if (c !== null && c !== undefined && c !== false) e.append(c);
  return e;
}
