// What the page may say about its clock (issue 38, item 8). The wasm core times every estimate
// with the run worker's performance.now(), which browsers round to a step: about 5 us when the
// page is cross-origin isolated (its server sent COOP/COEP), 100 us otherwise (a plain static
// host such as GitHub Pages cannot send those headers). Times under CLOCK_STEPS_FITTED steps are
// drawn but neither fitted nor compared, and no winner is named from them; when the clock could
// not be measured at all, no timing is compared.
//
// The step and the isolation are measured in the run worker (worker.js, READY) and kept as
// state.clockStep (ms) and state.isolated. Pure: no DOM (web/test/claims_race_clock.test.mjs).
import { CLOCK_STEPS_FITTED } from '../series/time.js';

/** A step above this (ms) is coarse even on an isolated page (Chromium isolated: 0.005 ms). */
export const FINE_CLOCK_MS = 0.02;

/** A duration in ms as the page writes it: "0.1 ms", "2 ms", "5 µs" (two significant digits). */
export function clockText(ms) {
  if (!(ms > 0) || !Number.isFinite(ms)) return '—';
  const two = (v) => String(Number(v.toPrecision(2)));
  return ms >= 0.05 ? `${two(ms)} ms` : `${two(ms * 1000)} µs`;
}

/**
 * The clock's claim from {stepMs, isolated} (isolated: true, false, or null when unknown):
 * {floorSeconds (null: unknown clock, compare nothing), banner (null: nothing to warn about),
 *  text, short, severity, holds, evidence, timeNote, raceNote, coarse}.
 * `timeNote` replaces the time plot note's clause about the clock (it is followed by ": times
 * under 20 steps (shaded) are drawn but left out of the slope"); `raceNote` ends the race card's
 * note ("… measured in the worker by the browser's clock, " + raceNote + ".").
 */
export function clockClaim({ stepMs = null, isolated = null } = {}) {
  const iso = isolated === true ? true : isolated === false ? false : null;
  if (!(typeof stepMs === 'number' && Number.isFinite(stepMs) && stepMs > 0)) {
    const text = 'The clock could not be measured: no timing is compared.';
    return {
      floorSeconds: null,
      coarse: true,
      banner: text,
      text,
      short: 'clock unknown',
      severity: 'warning',
      holds: null,
      evidence: { stepMs: null, isolated: iso, steps: CLOCK_STEPS_FITTED, floorSeconds: null },
      timeNote: 'The browser\'s clock could not be measured here, so no timing is compared. Where it can be, it rounds to a step',
      raceNote: 'which could not be measured here: no times are compared and no winner is named',
    };
  }
  const floorMs = CLOCK_STEPS_FITTED * stepMs;
  const floorSeconds = floorMs / 1000;
  const step = clockText(stepMs);
  const floor = clockText(floorMs);
  const coarse = iso !== true || stepMs > FINE_CLOCK_MS;
  const consequence = `times under ${floor} are drawn but neither fitted nor compared, and no winner is named from them`;
  let banner = null;
  if (iso === false && stepMs > FINE_CLOCK_MS) {
    banner = 'This page is not cross-origin isolated (a static host cannot send COOP/COEP), so the browser\'s clock '
      + `steps by ${step}: ${consequence}.`;
  } else if (iso === false) {
    banner = `This page is not cross-origin isolated (a static host cannot send COOP/COEP), but the browser's clock still steps by only ${step}: ${consequence}.`;
  } else if (iso === true && coarse) {
    banner = `This page is cross-origin isolated, but the browser's clock steps by ${step}: ${consequence}.`;
  } else if (iso === null) {
    banner = `The page could not tell whether it is cross-origin isolated; the browser's clock steps by ${step}: ${consequence}.`;
  }
  const why = iso === true ? 'this page is cross-origin isolated' : iso === false ? 'this page is not cross-origin isolated' : 'cross-origin isolation unknown';
  const text = banner || `The browser's clock steps by ${step} here (${why}): times under ${floor} (${CLOCK_STEPS_FITTED} steps) are drawn but neither fitted nor compared.`;
  return {
    floorSeconds,
    coarse,
    banner,
    text,
    short: `clock step ${step}`,
    severity: banner ? (stepMs > FINE_CLOCK_MS ? 'warning' : 'note') : 'info',
    holds: true,
    evidence: { stepMs, isolated: iso, steps: CLOCK_STEPS_FITTED, floorSeconds },
    timeNote: `The browser's clock steps by ${step} here (${why}), so ${CLOCK_STEPS_FITTED} steps are ${floor}`,
    raceNote: `which steps by ${step} here (${why}): a median time under ${floor} (${CLOCK_STEPS_FITTED} steps) is not compared, and no winner is named from it`,
  };
}

/** The clock's floor (s) of a clock argument: a clockClaim, or {stepMs, isolated}; null when the
 *  clock is unknown (then no time may be compared). */
export function clockFloor(clock) {
  if (clock && Object.prototype.hasOwnProperty.call(clock, 'floorSeconds')) return clock.floorSeconds ?? null;
  return clockClaim(clock || {}).floorSeconds;
}
