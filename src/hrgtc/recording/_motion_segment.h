/* The at-rest detector's tests of one segment (segment_tests), its guards and isolated runs.
 *
 * Part of _motion_native.c, which includes it once (one translation unit: the functions
 * are static). */
#ifndef HRGTC_MOTION_SEGMENT_H
#define HRGTC_MOTION_SEGMENT_H

/* ------------------------------------------------------------- one segment's tests */

typedef struct {  /* ChannelTests (_motion_kernel.py) */
    Py_ssize_t baseline_blocks, var_rows, min_run;
    double level_limit, diff_sigma, diff_centre, mad_to_sigma, variance_limit, clip_limit,
        high, low;
    Py_ssize_t clip_samples;
    int sigma_positive, held;
} Tests;

/* _anchors: the running median of the block medians at the block centres, the slopes
 * between them (medians, centres: `blocks` each; slopes: blocks - 1). */
static int anchors(const double *t, const double *values, const idx *edges, idx blocks,
                   idx baseline_blocks, double *medians, double *centres, double *slopes,
                   double *work)
{
    for (idx k = 0; k < blocks; k++) {
        idx a = edges[k], b = edges[k + 1];
        if (long_median(values + a, b - a, work, &medians[k]) != 0) return -1;
        centres[k] = 0.5 * (t[a] + t[b - 1]);
    }
    if (blocks >= 3) {  /* symmetric windows (shrinking at the ends) */
        idx half = baseline_blocks / 2;
        double *running = work + blocks;  /* work holds >= 2 blocks + 2 half + 1 */
        for (idx k = 0; k < blocks; k++) {
            idx r = half < k ? half : k;
            if (blocks - 1 - k < r) r = blocks - 1 - k;
            idx w = 2 * r + 1;
            memcpy(work, medians + k - r, sizeof(double) * (size_t)w);
            np_sort(work, w);
            running[k] = work[w / 2];
        }
        memcpy(medians, running, sizeof(double) * (size_t)blocks);
    }
    for (idx k = 0; k + 1 < blocks; k++)
        slopes[k] = (medians[k + 1] - medians[k]) / (centres[k + 1] - centres[k]);
    return 0;
}

/* _level_at: the baseline at time x; *j the interval of the last call */
static inline double level_at(double x, idx *j, const double *medians,
                              const double *centres, const double *slopes, idx last)
{
    if (last == 0) return medians[0];
    if (x < centres[0]) return medians[0] + slopes[0] * (x - centres[0]);
    if (x > centres[last]) return medians[last] + slopes[last - 1] * (x - centres[last]);
    if (x == centres[last]) return medians[last];
    while (centres[*j + 1] <= x) (*j)++;
    if (centres[*j] == x) return medians[*j];
    return slopes[*j] * (x - centres[*j]) + medians[*j];
}

/* _run_step: a streamed run finder; runs of at least `minimum` are OR-ed into out */
static inline idx run_step(int on, idx i, idx start, idx minimum, uint8_t *out)
{
    if (on) return start < 0 ? i : start;
    if (start >= 0 && i - start >= minimum)
        for (idx k = start; k < i; k++) out[k] = 1;
    return -1;
}

/* _variance_test (see its docstring in the numba reference) */
static void variance_test(const double *values, idx m, idx var_rows, double centre,
                          double mad_to_sigma, double limit, uint8_t *variance,
                          double *scratch)
{
    idx blocks = m / var_rows;
    double threshold = limit / mad_to_sigma;
    double delta = 0.25 * threshold;
    double quiet = threshold * (1.0 - 1e-6) - delta;
    double loud = threshold * (1.0 + 1e-6) + delta;
    double low = centre - delta, high = centre + delta;
    for (idx k = 0; k < blocks; k++) {
        idx a = k * var_rows;
        idx b = k < blocks - 1 ? (k + 1) * var_rows : m - 1;
        idx count = b - a, k_lo = (count - 1) / 2, k_hi = count / 2;
        idx below = 0, upto = 0, near = 0, far = 0;
        for (idx i = a; i < b; i++) {
            double d = values[i + 1] - values[i];
            below += d < low;
            upto += d <= high;
            double deviation = fabs(d - centre);
            near += deviation <= quiet;
            far += deviation <= loud;
        }
        if (below <= k_lo && upto >= k_hi + 1 && near >= k_hi + 1) continue;
        if (!(below <= k_lo && upto >= k_hi + 1 && far <= k_lo)) {
            double *block = scratch, *spread = scratch + count;
            for (idx i = a; i < b; i++) block[i - a] = values[i + 1] - values[i];
            memcpy(spread, block, sizeof(double) * (size_t)count);
            double middle = np_median(spread, count);
            for (idx i = 0; i < count; i++) spread[i] = fabs(block[i] - middle);
            if (!(mad_to_sigma * np_median(spread, count) > limit)) continue;
        }
        idx stop = k == blocks - 1 ? m : (k + 1) * var_rows;
        for (idx i = a; i < stop; i++) variance[i] = 1;
    }
}

/* segment_tests over m samples; out: level, variance, clipped, stepped. -1: no memory */
static int segment_tests(const double *t, const double *values, idx m, const idx *edges,
                         idx blocks, const Tests *c, uint8_t *const out[4])
{
    uint8_t *level = out[0], *variance = out[1], *clipped = out[2], *stepped = out[3];
    idx longest = 0;
    for (idx k = 0; k < blocks; k++)
        if (edges[k + 1] - edges[k] > longest) longest = edges[k + 1] - edges[k];
    idx size = longest;
    if (size < 2 * blocks + 2 * c->baseline_blocks + 2)
        size = 2 * blocks + 2 * c->baseline_blocks + 2;
    if (size < 4 * c->var_rows + 2) size = 4 * c->var_rows + 2;  /* a block and |d - m| */
    double *work = malloc(sizeof(double) * (size_t)(size + 3 * blocks));
    if (!work) return -1;
    double *medians = work + size, *centres = medians + blocks, *slopes = centres + blocks;
    if (anchors(t, values, edges, blocks, c->baseline_blocks, medians, centres, slopes,
                work) != 0) {
        free(work);
        return -1;
    }
    idx last = blocks - 1, j = 0;
    idx run_level = -1, run_high = -1, run_low = -1, run_step_ = -1;
    double limit = c->level_limit;
    for (idx i = 0; i <= m; i++) {
        int on_level = 0, on_high = 0, on_low = 0, on_step = 0;
        if (i < m) {
            double x = t[i], v = values[i];
            double base = level_at(x, &j, medians, centres, slopes, last);
            double left, right;  /* _held: the anchors either side of x */
            if (last == 0 || x <= centres[0]) {
                left = right = medians[0];
            } else if (x >= centres[last]) {
                left = right = medians[last];
            } else {
                left = medians[j];
                right = medians[j + 1];
            }
            on_step = c->sigma_positive && fabs(v - base) > limit;
            on_level = (on_step || (c->sigma_positive && c->held && fabs(right - left) > limit))
                       && fabs(v - left) > limit && fabs(v - right) > limit;
            on_high = v == c->high && fabs(c->high - base) > c->clip_limit;
            on_low = v == c->low && fabs(c->low - base) > c->clip_limit;
        }
        run_level = run_step(on_level, i, run_level, c->min_run, level);
        run_step_ = run_step(on_step, i, run_step_, c->min_run, stepped);
        run_high = run_step(on_high, i, run_high, c->clip_samples, clipped);
        run_low = run_step(on_low, i, run_low, c->clip_samples, clipped);
    }
    if (c->diff_sigma > 0 && m >= c->var_rows)
        variance_test(values, m, c->var_rows, c->diff_centre, c->mad_to_sigma,
                      c->variance_limit, variance, work);
    free(work);
    return 0;
}

/* guard: each run of any found mask extended inside its segment; guarded: by it alone */
static void guard(const uint8_t *const found[4], const idx *starts, const idx *stops,
                  idx segments, idx after, idx before, uint8_t *moving, uint8_t *guarded,
                  idx n)
{
    const uint8_t *level = found[0], *variance = found[1], *clipped = found[2],
                  *accel = found[3];
    for (idx k = 0; k < segments; k++) {
        idx a = starts[k], b = stops[k], start = -1;
        for (idx i = a; i <= b; i++) {
            int on = i < b && (level[i] | variance[i] | clipped[i] | accel[i]);
            if (on && start < 0) {
                start = i;
            } else if (!on && start >= 0) {
                idx from = start - before > a ? start - before : a;
                idx to = i + after < b ? i + after : b;
                for (idx q = from; q < to; q++) moving[q] = 1;
                start = -1;
            }
        }
    }
    for (idx i = 0; i < n; i++)
        guarded[i] = moving[i] & !(level[i] | variance[i] | clipped[i] | accel[i]);
}

static void isolated_runs(const uint8_t *stepped, const uint8_t *near, uint8_t *out, idx n)
{
    idx start = -1;
    int touched = 0;
    for (idx i = 0; i <= n; i++) {
        int on = i < n && stepped[i];
        if (on) {
            if (start < 0) {
                start = i;
                touched = 0;
            }
            touched |= near[i];
        } else if (start >= 0) {
            if (!touched)
                for (idx k = start; k < i; k++) out[k] = 1;
            start = -1;
        }
    }
}


#endif /* HRGTC_MOTION_SEGMENT_H */
