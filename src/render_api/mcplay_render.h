/* mcplay render C API: small glTF scenes rendered with radiance estimators, and their
 * convergence studies. Same conventions as mcplay.h (status codes, mcp_last_error,
 * JSON in and out, results released with mcp_free). Built as a separate library (and a
 * separate WebAssembly module) so that the integration playground does not carry it.
 *
 * Scene JSON: a render scene (docs/render-scenes.md). Options JSON (may be NULL): base_dir
 * (folder that a relative glTF path is resolved against), cache_dir (where high-spp references
 * are cached; none when absent), overrides of the scene's render settings: width, height,
 * spp_min, spp_max, reps, seed, threads, estimators, reference, jitter_pixels, exposure, accel;
 * pixel_sampler (every estimator's, not the reference's); and reference_data (a reference made
 * earlier: the reference_data of mcp_render_reference, used when it was made from the same
 * glTF, scene name, image size and reference settings, else rendered again and said so). */
#ifndef MCPLAY_RENDER_H
#define MCPLAY_RENDER_H

#include "api/mcplay.h"

#ifdef __cplusplus
extern "C" {
#endif

/* Convergence study: every estimator at spp = spp_min..spp_max (powers of two), reps
 * images each, measured by relative MSE against the reference (docs/result-schema.md,
 * "Render studies"). progress gets one JSON line per completed spp level, and before them,
 * while a reference is rendered, lines {"kind": "render_reference", "rows_done", "rows"}
 * (non-zero return cancels). Options also take previews (true: PNGs of each estimator's last image
 * and of the reference, base64, in the result). */
int mcp_render_study_run(const char* scene_json, const char* options_json, mcp_progress_fn progress,
                         void* user, char** result_json);

/* A study split over processes: each runs mcp_render_study_run with options.part = i of
 * options.parts = K (the replicates r with r % K == i), and its result carries every level's
 * images and "part": {"index", "of"}. parts_json is {"parts": [the K results]}; the merge is
 * the whole study's result, levels, fit and warnings bit for bit as one process would give them
 * (seconds are each image's own). Parts cut short merge over the levels all of them finished. */
int mcp_render_study_merge(const char* parts_json, char** result_json);

/* The study's reference image alone, obtained as a study obtains it (options.reference_data,
 * the cache, or rendered and then cached; an error for a scene whose reference is a file):
 * {"version", "kind": "render_reference", "scene", "source", "estimator", "spp", "seed",
 * "seconds" (when rendered), "width", "height", "mean_luminance", "relative_mse_floor",
 * "reference_data": the image, its variances and the key of what it was made from, base64}.
 * progress gets {"kind": "render_reference", "rows_done", "rows"} lines while it renders, as
 * mcp_render_study_run does before its levels (non-zero return cancels: no result). */
int mcp_render_reference(const char* scene_json, const char* options_json, mcp_progress_fn progress,
                         void* user, char** result_json);

/* What a study of the same scene and options would cost, before any of it is rendered:
 * validates like mcp_render_study_run (the same errors), then times a pilot (each estimator
 * renders one image of at most 64 x 64 pixels at 1 spp) and returns {"version", "kind":
 * "render", "samples", "limit_samples", "predicted_seconds", "threads", "levels", "reps",
 * "pilot_samples", "reference": {"source": file|cache|rendered, "spp", "samples",
 * "predicted_seconds"}, "estimators": [{"name", "samples", "seconds_per_sample",
 * "predicted_seconds"}]}. */
int mcp_render_study_plan(const char* scene_json, const char* options_json, char** plan_json);

/* One image: options.estimator (a name from the scene or an estimator object; default the
 * scene's best, the reference's), options.spp (default spp_max), options.outputs (any of "png",
 * "hdr", "pfm", "error_png"; default ["png"]; "error_png" renders or reads the reference). The
 * result carries the images base64-encoded, the diagnostics and the rays per second. With the
 * outputs "reference_png" and/or "reference_hdr" alone, the result is the study's reference
 * image (options.reference_data, the cache, its file, or rendered) and its "reference" block. */
int mcp_render_image(const char* scene_json, const char* options_json, char** result_json);

/* The points one pixel's samples take from a render pixel sampler, for the sampler lab:
 * request {"pixel_sampler": "independent" | "stratified" | "sobol" (default) | "padded_sobol",
 * "spp" (1..65536; a power of two for sobol; default 64), "dim" (2, 4, 6 or 8: the sample's first
 * dim / 2 2D requests, default 2), "seed" (the image's key, default 1), "width", "height" (the
 * image, default 1 x 1), "pixel": [x, y] (default [0, 0])}. Result: {"pixel_sampler", "n", "dim",
 * "seed", "width", "height", "pixel", "points": [[u_1, ..., u_dim] per sample]}, rows as
 * mcp_points_analyze takes them. */
int mcp_render_pixel_points(const char* request_json, char** points_json);

/* The live view: images that converge pass by pass (render/progressive.h). A session holds one
 * scene, 1 to 4 estimators and, for the rows [row_begin, row_end) of an image of width x height
 * pixels, each estimator's running pixel moments; a pass adds samples to one estimator's band.
 * Bands of one image rendered in several sessions (the page's workers) merge into the image one
 * session rendering every row gives, bit for bit, and passes to 1, 2, 4, ... spp leave the image
 * a one-shot render of that spp gives (same seed, estimator and pixel sampler).
 *
 * mcp_render_live_open: the scene JSON and options as mcp_render_image's (width, height, seed,
 * threads, exposure, reference_data, base_dir, cache_dir, pixel_sampler), and
 *   estimators: names from the scene or estimator objects, 1 to 4 (default the scene's first
 *     four);
 *   pixel_sampler: "padded_sobol" (default) or "independent": the samplers whose samples do not
 *     depend on the final spp ("stratified" and "sobol" are refused, saying why);
 *   long_side: without width and height, the image's longer side (16..4096, default 256), the
 *     other from the camera's aspect ratio (the glTF's aspectRatio, else the scene's width /
 *     height; refused beyond 8:1);
 *   rows: [row_begin, row_end] (default every row);
 *   live_reference: "obtain" (default: the reference as a study obtains it, rendered and cached
 *     when there is no other; progress lines {"kind": "render_reference", "rows_done", "rows"},
 *     non-zero return cancels) or "available" (only a file, options.reference_data or the cache:
 *     never rendered; the session then has none until mcp_render_live_reference gives one);
 *   pixels: true to return float32 pixels (below).
 * Result: {"version", "kind": "render_live", "session" (an integer > 0), "scene", "width",
 * "height", "rows": [begin, end], "pixel_sampler", "stream_seed", "estimators": [objects],
 * "reference": null or {"source", "spp", "mean_luminance", "relative_mse_floor", "rgb_f32" (with
 * pixels: the band's reference, base64 little-endian float32 RGB, rows from row_begin)},
 * "warnings"}.
 *
 * mcp_render_live_pass: pass_json {"estimator": index (0-based, in the session's list), "spp":
 * the samples per pixel the band is taken to (more than it has; at most 2^20), "pixels": bool,
 * "outputs": any of "png", "hdr" (the band as image files, base64, for the CLI)}. Result:
 * {"estimator", "spp", "seconds" (the band's rendering time over all its passes), "pass_seconds",
 * "samples", "rays", "discarded_nonfinite", "dominated_pixels", "rows", "error": null (no
 * reference) or {"sum", "sum_raw", "terms"} (the band's sums of the relative MSE's terms against
 * the reference, docs/result-schema.md: the image's relative MSE is the sum over bands of "sum"
 * divided by the sum of "terms"), "rgb_f32" (with pixels), "images" (with outputs)}. A cancelled
 * pass (progress returns non-zero: one line {"kind": "render_live_pass", "rows_done", "rows"}
 * per row) fails with MCP_ERROR_CANCELLED and the estimator's band takes no more passes.
 *
 * mcp_render_live_reference: gives a session its reference: reference_json {"reference_data":
 * mcp_render_reference's, made at the session's image size}; result as the open's "reference".
 * mcp_render_live_close: frees a session (unknown ids are an error). At most 16 sessions are
 * open at once. */
int mcp_render_live_open(const char* scene_json, const char* options_json, mcp_progress_fn progress,
                         void* user, char** result_json);
int mcp_render_live_pass(int session, const char* pass_json, mcp_progress_fn progress, void* user,
                         char** result_json);
int mcp_render_live_reference(int session, const char* reference_json, char** result_json);
int mcp_render_live_close(int session);

/* What a render scene holds: triangles, lights, materials, camera, accelerator, loader
 * warnings, estimators and settings. */
int mcp_render_scene_info(const char* scene_json, const char* options_json, char** info_json);

#ifdef __cplusplus
}
#endif

#endif
