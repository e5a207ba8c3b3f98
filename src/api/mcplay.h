/* mcplay C API: the one boundary shared by the CLI, the tests and the WebAssembly exports.
 *
 * Requests and results are JSON strings (schemas in docs/scene-format.md and
 * docs/result-schema.md). Every function returns a status code; on failure
 * mcp_last_error() gives a one-line message naming what is wrong. No C++ exception crosses
 * this boundary. Strings returned through `char** out` are owned by the caller and freed
 * with mcp_free(). */
#ifndef MCPLAY_H
#define MCPLAY_H

#include <stdint.h>

#ifdef __cplusplus
extern "C" {
#endif

typedef enum mcp_status {
    MCP_OK = 0,
    MCP_ERROR_ARGUMENT = 1,  /* a NULL pointer or a malformed options/format argument */
    MCP_ERROR_SCENE = 2,     /* the scene JSON is malformed or names something invalid */
    MCP_ERROR_CANCELLED = 3, /* the progress callback asked to stop (partial result given) */
    MCP_ERROR_INTERNAL = 4,  /* a bug: please report the message */
    MCP_ERROR_FUNCTION = 5   /* a caller's function (mcp_function) returned non-zero */
} mcp_status;

/* Called after each completed N of a study with that level's results as JSON
 * ({"level_index", "n", "estimators": [...]}). Return 0 to go on, non-zero to cancel. */
typedef int (*mcp_progress_fn)(const char* level_json, void* user);

/* Library version, e.g. "0.1.0". */
const char* mcp_version(void);

/* Message of the last failed call on this thread ("" if none). */
const char* mcp_last_error(void);

/* Runs a convergence study of the scene. options_json may be NULL or override the scene's
 * settings: {"estimators": [names], "n_min", "n_max", "reps", "seed", "threads"}.
 * progress may be NULL. On MCP_OK or MCP_ERROR_CANCELLED *result_json holds the result. */
int mcp_study_run(const char* scene_json, const char* options_json, mcp_progress_fn progress,
                  void* user, char** result_json);

/* A study split over processes: each runs mcp_study_run with options.part = i of
 * options.parts = K (1 <= K <= min(reps, 1024)), which runs only the replicates r with
 * r % K == i and returns a part {"kind": "study_part" or "stopping_part", "part": {"index",
 * "of"}, "scene", "options", "threads", "wall_time_s", "estimators": [every replicate's run,
 * written exactly]} (no progress calls). parts_json is {"parts": [the K parts]}: same scene,
 * same options but threads, each index once. The merge is the result mcp_study_run gives for
 * the whole study, bit for bit but for the timing fields (wall_time_s, settings.threads: the
 * parts' largest; the levels' time_*, training_time_mean and efficiency, from each replicate's
 * own seconds). A part whose settings, replicates or numbers do not fit is refused with the
 * field named (MCP_ERROR_ARGUMENT). */
int mcp_study_merge(const char* parts_json, char** result_json);

/* Validates a study exactly as mcp_study_run does (including the size limits: at most 2^40
 * integrand evaluations, sum over N of N x reps x estimators, and 2^21 replicate results) and
 * predicts its cost from a timed pilot of 4096 samples per estimator (a few ms), without running
 * it. Result: {"version", "evaluations", "limit_evaluations", "predicted_seconds", "threads",
 * "levels": [N...], "n_min", "n_max", "reps", "pilot_samples", "pilot_seconds", "estimators":
 * [{"name", "evaluations", "seconds_per_evaluation", "predicted_seconds"}]}. predicted_seconds
 * is wall time on "threads" threads, excluding the once-per-estimator support check. */
int mcp_study_plan(const char* scene_json, const char* options_json, char** plan_json);

/* The points behind a small run of each estimator, for plotting them: options_json may give
 * {"estimators": [names], "n": points (1..4096, default 256), "seed", "grid": 1D curve points
 * (default 256), "adaptive_n": calls of the adaptive estimators' run (1..2^20)}. Result:
 * {"version", "n", "estimators": [{"name", "kind", "method", "replay_is_estimate", "sampler",
 * "pdf", "pdf_text" (the density in words), "strata", "samples_per_stratum", "randomization",
 * "randomizations" (the estimator's own grid and randomizations), "u": [per axis], "x": [per
 * axis], "f", "density", "weight"}],
 * and for 1D box domains "curve": {"x", "f", "pdf": {name: density values}, "mis_weights":
 * {name: [per technique: weights]}}}. The points are those of replicate 0 of a study at N = n,
 * so the mean of "weight" is that replicate's estimate. "replay_is_estimate" (from the
 * estimator's kind): whether the mean of the first k weights is its estimate at N = k, with the
 * independent points' error bar. Adaptive estimators (VEGAS, MISER) run
 * at N = max(n, adaptive_n) ("run_n") and show the first n points of their estimate, with what
 * they learnt: "map_edges" (VEGAS's frozen map, per axis), "map_history" (the map's first two
 * axes before and after each training iteration, at most 65 edges each), "boxes" (MISER's
 * leaves). MIS estimators add "heuristic" and "techniques": [{"pdf", "pdf_text", "share"}]. */
int mcp_study_samples(const char* scene_json, const char* options_json, char** samples_json);

/* Formats a study result as "table" (human), "csv" or "json" (pretty-printed). The result must
 * have the documented shape ("estimators": [{..., "levels": [{...}]}]), else MCP_ERROR_ARGUMENT
 * naming the first field that is not (e.g. "result.estimators: expected an array, got number"). */
int mcp_result_format(const char* result_json, const char* format, char** text);

/* Validates a scene and summarises it: {"name", "description", "domain", "dimension",
 * "exact", "estimators": [names], "more_estimators": [uniform-density presets it does not list],
 * "estimator_details": [{"name", "kind", "summary" (the kind's), "method", "sampler", "pdf",
 * "pdf_text" (the density in words)}],
 * settings}. */
int mcp_scene_info(const char* scene_json, char** info_json);

/* What the library offers: "estimators" (the presets: {"name", "kind", "sampler", "needs_pdf",
 * "summary"}), "kinds" (the estimator kinds: {"name", "summary"}), "samplers", "randomizations"
 * (per quasi-Monte Carlo sampler), "pdfs", "integrands", "domains", "warps" (the named warps:
 * {"name", "summary"}). */
int mcp_catalog(char** catalog_json);

/* --- The sampler lab (docs/sampler-lab.md) --------------------------------------------- */

/* The points one sampler draws: request {"sampler" ("uniform" = "independent", "stratified",
 * "latin_hypercube", "sobol", "halton", "lattice"), "n" (1..2^20), "dim" (1..64), "seed",
 * "randomization" (quasi-Monte Carlo samplers; "none" for the deterministic points)}, at most
 * 2^22 numbers. Result: {"version", "sampler", "randomization", "n", "dim", "seed",
 * "points": [[x_1, ..., x_dim] per point]}. */
int mcp_points(const char* request_json, char** points_json);

/* Analyses point sets in [0,1)^d: request {"points": rows, or an array of K sets of rows} or
 * {"csv": text (a column "set" splits the rows into K sets)} or {"sampler": {as mcp_points, and
 * "sets": K}}, with "spectrum": false or {"axes": [a, b], "size": even S <= 1024 (default 256)}
 * and "pairwise": false to skip the O(N^2 d) measures. Result: {"version", "source", "n", "dim",
 * "sets", "set_names", "l2_star_discrepancy", "centered_l2_discrepancy",
 * "wraparound_l2_discrepancy", "min_distance", "min_distance_toroidal" (means over the sets;
 * null when skipped), "per_set": {measure: [per set]} (K > 1), "expected_iid": {the root mean
 * square discrepancies of N independent uniform points}, "spectrum": {"size", "axes", "power"
 * (S x S, row ky + S/2, column kx + S/2, averaged over the sets), "radial": {"frequency",
 * "power", "count"}}, "skipped": {measure: why}}. */
int mcp_points_analyze(const char* request_json, char** analysis_json);

/* Discrepancy against N for several samplers (the Koksma-Hlawka picture): request {"samplers":
 * [names], "dim", "n_min", "n_max" (<= 65536; powers of two between), "seed", "reps" (<= 64),
 * "scene" (optional: a problem with an exact value whose integration error is measured with the
 * same points)}. Result: {"version", "dim", "reps", "seed", "statistic", "curves": [{"sampler",
 * "n", "l2_star_discrepancy", "wraparound_l2_discrepancy", "rms_error"?}], "problem"?, "exact"?}:
 * root mean squares over reps independent sets. */
int mcp_discrepancy_curve(const char* request_json, char** curve_json);

/* A scene's problem integrated with point sets given whole (request as mcp_points_analyze's
 * "points" / "csv" / "sampler"): {"version", "problem", "source", "n", "sets", "estimate",
 * "per_set", "evaluations", "exact", "error", "error_bar": null for one set (a deterministic rule,
 * "note" says so), else {"standard_error", "half_width_95", "degrees_of_freedom", "method"}}. */
int mcp_points_integrate(const char* scene_json, const char* request_json, char** result_json);

/* Tests a warp (docs/scene-format.md, "warp"): its density integrates to 1, and a chi-square
 * test of its samples against that density in equal-measure bins. options_json may be NULL or
 * {"samples", "seed", "significance", "tests" (Sidak), "bins": [per natural coordinate]}.
 * A failed test is a result (MCP_OK, "outcome": "failed", "passed": false), and so is one the
 * quadrature could not settle ("outcome": "unverified", "passed": null, "verdict" says why:
 * docs/result-schema.md, The sampler lab's results); a warp that cannot be tested (g leaves
 * the domain, p negative or NaN) is MCP_ERROR_SCENE naming the sample or the point. */
int mcp_warp_test(const char* scene_json, const char* options_json, char** result_json);

/* --- Functions given by the caller (a Python callable, a JavaScript function) ----------------
 *
 * A scene names a caller's function where it would give an expression: the integrand
 * ("integrand" or "f": {"type": "function", "name": N}) and a typed warp's map and density
 * ("warp": {"domain", "g": {"function": N, "sample_dim": k}, "p": {"function": N}}). The
 * function gets a whole block of points at a time (never one call per point), column-major
 * (structure of arrays, as the core holds them): x[j * n + i] is coordinate j of point i
 * (i < n), and it writes out[k * n + i] (out_dim 1 for an integrand or a density, the domain's
 * point dimension for a warp's map): numpy's order='F' (n, in_dim) array. It
 * may be called from several of the call's threads at once. A return of non-zero stops the
 * call that uses it within a block: no further calls are made, and the call fails with
 * MCP_ERROR_FUNCTION (its message names the function); the function's owner keeps the reason.
 * Calls that take no mcp_context refuse a scene naming a function. */
typedef int (*mcp_batch_fn)(void* user, const double* x, uint64_t n, int in_dim, double* out,
                            int out_dim);
typedef struct mcp_function {
    const char* name; /* as the scene names it: 1 to 64 characters */
    mcp_batch_fn fn;
    void* user;
} mcp_function;

/* Polled between blocks, from any of the call's threads: non-zero cancels the call (a study
 * then ends with MCP_ERROR_CANCELLED and its partial result, as a cancelling progress callback
 * does, but within a block rather than after a level). */
typedef int (*mcp_cancel_fn)(void* user);

typedef struct mcp_context {
    const mcp_function* functions; /* may be NULL when function_count is 0 */
    int function_count;            /* 0..16 */
    mcp_cancel_fn cancel;          /* may be NULL */
    void* cancel_user;
} mcp_context;

/* mcp_study_run, mcp_study_plan and mcp_warp_test with a context (ctx may be NULL: then they
 * are the calls above). */
int mcp_study_run_with(const char* scene_json, const char* options_json, const mcp_context* ctx,
                       mcp_progress_fn progress, void* user, char** result_json);
int mcp_study_plan_with(const char* scene_json, const char* options_json, const mcp_context* ctx,
                        char** plan_json);
int mcp_warp_test_with(const char* scene_json, const char* options_json, const mcp_context* ctx,
                       char** result_json);

/* Frees a string returned by this API. */
void mcp_free(char* p);

#ifdef __cplusplus
}
#endif

#endif /* MCPLAY_H */
