// Types of the package's main entry ("mcplay"): the integration core (index.js over
// web/core.js). Results are the C API's JSON (docs/result-schema.md in the repository): the
// fields typed here are the ones most callers read; every object keeps the rest as `unknown`.

/** A JSON object as the C API reads or writes it. */
export type JsonObject = { [key: string]: unknown };

/** A scene, options or result: an object, or the same as JSON text. */
export type JsonInput<T extends object = JsonObject> = T | string;

/** Status codes of src/api/mcplay.h (enum mcp_status). */
export declare const Status: Readonly<{
  OK: 0;
  ARGUMENT: 1;
  SCENE: 2;
  CANCELLED: 3;
  INTERNAL: 4;
  /** A caller's function failed (the C API's mcp_*_with calls; not exported to wasm yet). */
  FUNCTION: 5;
}>;

/** One of the values of `Status`. */
export type StatusCode = (typeof Status)[keyof typeof Status];

/** A failed call: `status` is the C status code, `message` the C API's one-line error. */
export declare class McplayError extends Error {
  constructor(status: number, message: string);
  readonly name: 'McplayError';
  /** The C status code (`Status`). */
  readonly status: number;
  /** Its name: "ARGUMENT", "SCENE", "CANCELLED", "INTERNAL", "FUNCTION". */
  readonly statusName: string;
}

/** The largest JSON text sent to the core, in bytes (the C side's limit). */
export declare const MAX_JSON_BYTES: number;

/** Emscripten module options given to the wasm module's factory. */
export interface ModuleOptions {
  /** The .wasm file's bytes (replaces the package's own file). */
  wasmBinary?: ArrayBuffer | Uint8Array;
  /** Where the .wasm is, for a copy served elsewhere. */
  locateFile?: (path: string, prefix: string) => string;
  [option: string]: unknown;
}

/** An integration scene (docs/scene-format.md): an expression `f`, or a library integrand. */
export interface Scene extends JsonObject {
  name?: string;
  description?: string;
  /** The integrand as an expression, e.g. "exp(-(x-0.5)^2/0.01)". */
  f?: string;
  /** The known value of the integral, if any. */
  exact?: number | null;
  estimators?: Array<string | JsonObject>;
  n_min?: number;
  n_max?: number;
  reps?: number;
  seed?: number;
}

/** What a study runs; every field overrides the scene's own. */
export interface StudyOptions extends JsonObject {
  /** Estimator names from the scene or the catalog, or estimator objects. */
  estimators?: Array<string | JsonObject>;
  n_min?: number;
  n_max?: number;
  reps?: number;
  seed?: number;
  threads?: number;
  /** Stop at a requested accuracy instead of running an N ladder ("kind": "stopping"). */
  rel_tol?: number;
  abs_tol?: number;
  /** Run replicates r with r % parts === part only (a part of a split study). */
  part?: number;
  parts?: number;
}

/** A flag raised on a level, an estimator or a stopping run. */
export interface Warning extends JsonObject {
  code: string;
  severity: 'info' | 'warning' | 'error' | string;
  message: string;
}

/** One N of an estimator's ladder. */
export interface Level extends JsonObject {
  n: number;
  reps: number;
  mean: number | null;
  variance: number | null;
  std_error: number | null;
  ci95: [number, number] | null;
  mse: number | null;
  coverage95: number | null;
  time_mean_s: number | null;
  efficiency: number | null;
  warnings: Warning[];
  replicates: { estimate: Array<number | null>; std_error: Array<number | null> };
}

/** Least squares of log variance (or MSE) on log N. */
export interface Fit extends JsonObject {
  valid: boolean;
  measure: string;
  order: number | null;
  order_se: number | null;
  p_value: number | null;
}

/** One estimator's part of a study result. */
export interface EstimatorResult extends JsonObject {
  name: string;
  kind: string;
  method: string;
  sampler: string;
  error_method: string;
  warnings: Warning[];
  /** The N ladder (absent in a stopping study, which has `runs`). */
  levels?: Level[];
  fit?: Fit;
  mse_fit?: Fit;
  runs?: JsonObject[];
}

/** The result of runStudy: the same JSON as `mcplay run --format json`. */
export interface StudyResult extends JsonObject {
  version: number;
  /** The library version. */
  mcplay: string;
  /** Absent for an N ladder; "stopping" or "study_part" otherwise. */
  kind?: string;
  scene: JsonObject & {
    name: string;
    exact: number | null;
  };
  settings: JsonObject;
  cancelled: boolean;
  wall_time_s: number;
  estimators: EstimatorResult[];
}

/** The progress object given to onLevel after each N: {level_index, n, estimators}. */
export interface LevelProgress extends JsonObject {
  level_index: number;
  n: number;
  estimators: JsonObject[];
}

/** Called after each N; returning exactly `true` cancels the study. Must be synchronous. */
export type OnLevel = (progress: LevelProgress) => boolean | void;

/** Heap figures of the wasm instance, for leak checks. */
export interface HeapStats {
  memoryBytes: number;
  arenaBytes: number;
  allocatedBytes: number;
  freeBytes: number;
}

/** The integration core: one wasm instance; every call is synchronous and throws McplayError. */
export interface Core {
  /** The library version, e.g. "0.1.0" (mcp_version). */
  version(): string;
  /** What the library offers: estimators, kinds, samplers, randomizations, pdfs, integrands,
   *  domains, warps (mcp_catalog). */
  catalog(): JsonObject & {
    estimators: Array<JsonObject & { name: string; kind: string; summary: string }>;
    kinds: Array<JsonObject & { name: string; summary: string }>;
  };
  /** Validates a scene and summarises it (mcp_scene_info). */
  sceneInfo(scene: JsonInput<Scene>): JsonObject;
  /** The points behind a small run of each estimator (mcp_study_samples). */
  samples(scene: JsonInput<Scene>, options?: JsonInput | null): JsonObject;
  /** What a study would cost, from a pilot of a few ms; validates like runStudy (mcp_study_plan). */
  plan(scene: JsonInput<Scene>, options?: JsonInput<StudyOptions> | null): JsonObject;
  /** Runs a convergence study (mcp_study_run): the CLI's `run --format json` result. */
  runStudy(scene: JsonInput<Scene>, options?: JsonInput<StudyOptions> | null,
    onLevel?: OnLevel | null): StudyResult;
  /** A study result as "table" (the CLI's), "csv" or "json" text (mcp_result_format). */
  format(result: JsonInput<StudyResult>, format?: 'table' | 'csv' | 'json'): string;
  /** The points of one sampler (mcp_points). */
  points(request: JsonInput): JsonObject & { n: number; dim: number; points: number[][] };
  /** Discrepancies, minimum distances and spectrum of point sets (mcp_points_analyze). */
  analyzePoints(request: JsonInput): JsonObject;
  /** Discrepancy against N for several samplers (mcp_discrepancy_curve). */
  discrepancyCurve(request: JsonInput): JsonObject;
  /** A scene's problem integrated with point sets given whole (mcp_points_integrate). */
  integratePoints(scene: JsonInput<Scene>, request: JsonInput): JsonObject;
  /** The chi-square test of a scene's warp (mcp_warp_test). */
  warpTest(scene: JsonInput<Scene>, options?: JsonInput | null): JsonObject & { passed: boolean };
  /** Heap figures for leak checks. */
  heapStats(): HeapStats;
  /** Releases the core's progress trampoline; the core cannot be used afterwards. */
  dispose(): void;
}

/** The default export of an Emscripten glue module (mcplay_web.mjs). */
export type ModuleFactory = (options?: ModuleOptions) => Promise<unknown>;

/**
 * Instantiates the integration core from this package's mcplay_web.wasm: a new, independent
 * core per call. In Node the package reads the .wasm itself; in a browser or a bundle it is
 * fetched from beside the module.
 */
export declare function load(options?: ModuleOptions): Promise<Core>;

/** Instantiates the core from a glue module given by the caller (web/core.js's loadCore). */
export declare function loadCore(createMcplay: ModuleFactory, options?: ModuleOptions): Promise<Core>;
