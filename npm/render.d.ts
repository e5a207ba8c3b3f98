// Types of the package's "mcplay/render" entry: the render core (render.js over
// web/render_core.js). Results are the C API's JSON (docs/result-schema.md, "Render studies").
import type {
  Fit, HeapStats, JsonInput, JsonObject, Level, ModuleFactory, ModuleOptions, Warning,
} from './index.js';

export { McplayError, Status } from './index.js';
export type { HeapStats, JsonInput, JsonObject, ModuleFactory, ModuleOptions, StatusCode } from './index.js';

/** A render scene: `render.gltf` must be the glTF object itself (the wasm module reads no files). */
export interface RenderScene extends JsonObject {
  name?: string;
  description?: string;
  render: JsonObject & {
    gltf: JsonObject;
    width?: number;
    height?: number;
    spp_min?: number;
    spp_max?: number;
    reps?: number;
    estimators?: Array<string | JsonObject>;
  };
}

/** Options of a render study or image; every field overrides the scene's own. */
export interface RenderOptions extends JsonObject {
  estimators?: Array<string | JsonObject>;
  spp_min?: number;
  spp_max?: number;
  reps?: number;
  seed?: number;
  width?: number;
  height?: number;
  /** Each level's images as PNG (base64) in the progress objects. */
  previews?: boolean;
}

/** Options of renderImage. */
export interface ImageOptions extends JsonObject {
  /** An estimator name from the scene, or an estimator object (default: the scene's best). */
  estimator?: string | JsonObject;
  spp?: number;
  /** Image files to return, base64: "png", "hdr", "pfm", "error_png". Default ["png"]. */
  outputs?: Array<'png' | 'hdr' | 'pfm' | 'error_png' | 'reference_png' | 'reference_hdr'>;
  width?: number;
  height?: number;
  seed?: number;
}

/** The result of renderImage: {kind: "render_image", images: {png: base64, ...}, ...}. */
export interface RenderImageResult extends JsonObject {
  kind: 'render_image';
  width: number;
  height: number;
  images: { [output: string]: string };
  seconds: number;
  rays_per_second: number;
}

/** A render study's result: the shape of a study result, levels measured in relative MSE
 *  against the reference at spp = n (docs/result-schema.md, "Render studies"). */
export interface RenderStudyResult extends JsonObject {
  version: number;
  mcplay: string;
  kind: 'render';
  scene: JsonObject & { name: string; width: number; height: number; exact: number | null };
  settings: JsonObject;
  cancelled: boolean;
  wall_time_s: number;
  estimators: Array<JsonObject & {
    name: string;
    strategy: string;
    /** Whether each sample's reflected radiance is bounded by construction (then heavy_tail and
     * rare_large_errors are info), or its variance infinite by construction (then heavy_tail is
     * a warning whatever the tail reads); neither: the tail estimate decides.
     * docs/render-scenes.md, "Bounded contributions". */
    contribution_bound: { bounded: boolean; infinite_variance: boolean; reason: string };
    rays_per_second: number;
    warnings: Warning[];
    /** One per spp: `variance` is the relative MSE against the reference. */
    levels: Level[];
    fit: Fit;
  }>;
}

/** Called with each level of a render study; returning exactly `true` cancels it. */
export type OnRenderLevel = (progress: JsonObject & { kind: 'render'; level_index: number; n: number }) =>
  boolean | void;

/** Called while a study renders its reference: {kind: "render_reference", rows_done, rows}. */
export type OnReference = (progress: JsonObject & { kind: 'render_reference'; rows_done: number; rows: number }) =>
  boolean | void;

/** The render core: one wasm instance; every call is synchronous and throws McplayError. */
export interface RenderCore {
  /** The library version (mcp_version). */
  version(): string;
  /** What a render scene holds (mcp_render_scene_info). */
  sceneInfo(scene: JsonInput<RenderScene>, options?: JsonInput<RenderOptions> | null): JsonObject;
  /** What a study would cost, from a pilot (mcp_render_study_plan). */
  plan(scene: JsonInput<RenderScene>, options?: JsonInput<RenderOptions> | null): JsonObject;
  /** A render convergence study: relative MSE against spp (mcp_render_study_run). */
  runStudy(scene: JsonInput<RenderScene>, options?: JsonInput<RenderOptions> | null,
    onLevel?: OnRenderLevel | null, onReference?: OnReference | null): RenderStudyResult;
  /** One image (mcp_render_image). */
  renderImage(scene: JsonInput<RenderScene>, options?: JsonInput<ImageOptions> | null): RenderImageResult;
  /** The parts of a study split by replicate, merged (mcp_render_study_merge). */
  mergeParts(parts: Array<JsonInput<RenderStudyResult>>): RenderStudyResult;
  /** The points one pixel's samples take from a pixel sampler (mcp_render_pixel_points). */
  pixelPoints(request: JsonInput): JsonObject & { n: number; dim: number; points: number[][] };
  /** The study's reference image alone (mcp_render_reference). */
  reference(scene: JsonInput<RenderScene>, options?: JsonInput<RenderOptions> | null,
    onProgress?: OnReference | null): JsonObject & { kind: 'render_reference' };
  /** Opens a live session (mcp_render_live_open). */
  liveOpen(scene: JsonInput<RenderScene>, options?: JsonInput | null): JsonObject & { session: number };
  /** One pass of a live session (mcp_render_live_pass). */
  livePass(session: number, pass: JsonInput): JsonObject;
  /** Gives a live session its reference (mcp_render_live_reference). */
  liveReference(session: number, reference: JsonInput): JsonObject;
  /** Frees a live session (mcp_render_live_close). */
  liveClose(session: number): void;
  /** Heap figures for leak checks. */
  heapStats(): HeapStats;
  /** Releases the core's progress trampoline; the core cannot be used afterwards. */
  dispose(): void;
}

/** Instantiates the render core from this package's mcplay_render_web.wasm: a new core per call. */
export declare function load(options?: ModuleOptions): Promise<RenderCore>;

/** Instantiates the render core from a glue module given by the caller (loadRenderCore). */
export declare function loadRenderCore(createMcplayRender: ModuleFactory,
  options?: ModuleOptions): Promise<RenderCore>;
