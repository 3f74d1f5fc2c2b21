/* The at-rest detector's loops (hrgtc.recording.motion), in C.
 *
 * Private to hrgtc.recording (_motion_kernel.py wraps it: it allocates the outputs, this
 * fills them); built by `pip install -e .` (setup.py). Why C and not numba: a command
 * that runs the detector spent ~0.4 s loading its eight cached numba dispatchers, as much
 * as the loops (docs/architecture.md, "The native at-rest detector").
 *
 * Each kernel is the numba kernel it replaces, line for line (the numba text is kept in
 * tests/recording/_motion_numba_reference.py; test_motion_native.py compares the two bit
 * for bit). The medians, sorts and partitions are numba's own algorithms (numba 0.68's
 * np.median: quickselect with a median-of-three pivot and `<`; np.sort: its quicksort
 * with NaN last, insertion sort under 16 values; np.partition: the NaN-aware
 * quickselect; np.min: the first NaN or the first smallest), so even the sign of a zero
 * median and the place of a NaN are numba's. No fast-math, no FMA contraction (setup.py
 * passes -ffp-contract=off): every product and sum is rounded as written.
 */
#define PY_SSIZE_T_CLEAN
#include <Python.h>
#include <math.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>

typedef Py_ssize_t idx;

/* ------------------------------------------------------------- numba's selections */

static inline int lt_plain(double a, double b) { return a < b; }
static inline int lt_nan_aware(double a, double b)  /* numba's nan_aware_less_than */
{
    if (isnan(a)) return 0;
    if (isnan(b)) return 1;
    return a < b;
}
static inline int lt_floats(double a, double b)  /* numba's sort order: NaN last */
{
    return a < b || (isnan(b) && !isnan(a));
}

#define SWAP(A, i, j) do { double tmp_ = A[i]; A[i] = A[j]; A[j] = tmp_; } while (0)

/* numba's _partition / _select, one pair per comparison */
#define SELECTION(NAME, LT)                                                             \
    static idx partition_##NAME(double *A, idx low, idx high)                         \
    {                                                                                   \
        idx mid = (low + high) >> 1;                                                    \
        if (LT(A[mid], A[low])) SWAP(A, low, mid);                                      \
        if (LT(A[high], A[mid])) SWAP(A, high, mid);                                    \
        if (LT(A[mid], A[low])) SWAP(A, low, mid);                                      \
        double pivot = A[mid];                                                          \
        SWAP(A, high, mid);                                                             \
        idx i = low, j = high - 1;                                                      \
        for (;;) {                                                                      \
            while (i < high && LT(A[i], pivot)) i++;                                    \
            while (j >= low && LT(pivot, A[j])) j--;                                    \
            if (i >= j) break;                                                          \
            SWAP(A, i, j);                                                              \
            i++;                                                                        \
            j--;                                                                        \
        }                                                                               \
        SWAP(A, i, high);                                                               \
        return i;                                                                       \
    }                                                                                   \
    static double select_##NAME(double *A, idx k, idx low, idx high)                  \
    {                                                                                   \
        idx i = partition_##NAME(A, low, high);                                         \
        while (i != k) {                                                                \
            if (i < k) low = i + 1;                                                     \
            else high = i - 1;                                                          \
            i = partition_##NAME(A, low, high);                                         \
        }                                                                               \
        return A[k];                                                                    \
    }

SELECTION(plain, lt_plain)
SELECTION(nan, lt_nan_aware)

/* numba's _select_two: the k'th and k+1'th smallest of A[low..high] */
static void select_two(double *A, idx k, idx low, idx high, double *a, double *b)
{
    for (;;) {
        idx i = partition_plain(A, low, high);
        if (i < k) {
            low = i + 1;
        } else if (i > k + 1) {
            high = i - 1;
        } else if (i == k) {
            select_plain(A, k + 1, i + 1, high);
            break;
        } else {
            select_plain(A, k, low, i - 1);
            break;
        }
    }
    *a = A[k];
    *b = A[k + 1];
}

/* numba's np.median of the n values of A (reordered in place; NaN for none) */
static double np_median(double *A, idx n)
{
    if (n == 0) return NAN;
    idx half = n >> 1;
    if ((n & 1) == 0) {
        double a, b;
        select_two(A, half - 1, 0, n - 1, &a, &b);
        return (a + b) / 2;
    }
    return select_plain(A, half, 0, n - 1);
}

/* numba's np.partition(A, k)[k] (A reordered in place) */
static double np_partition_at(double *A, idx n, idx k) { return select_nan(A, k, 0, n - 1); }

/* numba's np.min (the first NaN, else the first smallest) */
static double np_min(const double *A, idx n)
{
    double m = A[0];
    if (isnan(m)) return m;
    for (idx i = 1; i < n; i++) {
        if (isnan(A[i])) return A[i];
        if (A[i] < m) m = A[i];
    }
    return m;
}

static void insertion_sort(double *A, idx low, idx high)
{
    for (idx i = low + 1; i <= high; i++) {
        double v = A[i];
        idx j = i;
        while (j > low && lt_floats(v, A[j - 1])) {
            A[j] = A[j - 1];
            j--;
        }
        A[j] = v;
    }
}

/* numba's quicksort (np.sort of float64): partitions until 15 values, then insertion */
static void np_sort(double *A, idx n)
{
    idx stack_lo[100], stack_hi[100];
    int top = 1;
    if (n < 2) return;
    stack_lo[0] = 0;
    stack_hi[0] = n - 1;
    while (top > 0) {
        top--;
        idx low = stack_lo[top], high = stack_hi[top];
        while (high - low >= 15 && top < 100) {
            idx mid = (low + high) >> 1;
            if (lt_floats(A[mid], A[low])) SWAP(A, low, mid);
            if (lt_floats(A[high], A[mid])) SWAP(A, high, mid);
            if (lt_floats(A[mid], A[low])) SWAP(A, low, mid);
            double pivot = A[mid];
            SWAP(A, high, mid);
            idx i = low, j = high - 1;
            for (;;) {
                while (i < high && lt_floats(A[i], pivot)) i++;
                while (j >= low && lt_floats(pivot, A[j])) j--;
                if (i >= j) break;
                SWAP(A, i, j);
                i++;
                j--;
            }
            SWAP(A, i, high);
            if (high - i > i - low) {
                if (high > i) {
                    stack_lo[top] = i + 1;
                    stack_hi[top++] = high;
                }
                high = i - 1;
            } else {
                if (i > low) {
                    stack_lo[top] = low;
                    stack_hi[top++] = i - 1;
                }
                low = i + 1;
            }
        }
        insertion_sort(A, low, high);
    }
}

/* ------------------------------------------------------------- the bracketing median */

/* _motion_kernel.median of n values; `work` holds at least n doubles (clobbered).
 * Returns 0, or -1 without memory. */
static int long_median(const double *values, idx n, double *work, double *out)
{
    if (n <= 2048) {
        memcpy(work, values, sizeof(double) * (size_t)n);
        *out = np_median(work, n);
        return 0;
    }
    idx step = n / 512, s = (n - 1) / step + 1;
    double *sample = malloc(sizeof(double) * (size_t)s);
    if (!sample) return -1;
    for (idx i = 0; i < s; i++) sample[i] = values[i * step];
    np_sort(sample, s);
    idx k_lo = (n - 1) / 2, k_hi = n / 2;
    idx margin = 2 * (idx)sqrt((double)s) + 8;
    idx at_lo = (idx)((double)k_lo / (double)n * (double)s) - margin;
    idx at_hi = (idx)((double)k_hi / (double)n * (double)s) + margin;
    double lo = sample[at_lo > 0 ? at_lo : 0], hi = sample[at_hi < s - 1 ? at_hi : s - 1];
    free(sample);
    idx below = 0, equal_lo = 0, equal_hi = 0, kept = 0;
    for (idx i = 0; i < n; i++) {
        double v = values[i];
        below += v < lo;
        equal_lo += v == lo;
        equal_hi += (v == hi) & (hi != lo);
        work[kept] = v;
        kept += (lo < v) & (v < hi);
    }
    idx r_lo = k_lo - below, r_hi = k_hi - below;
    if (r_lo < 0 || r_hi >= equal_lo + kept + equal_hi) {
        memcpy(work, values, sizeof(double) * (size_t)n);
        *out = np_median(work, n);
        return 0;
    }
    double picked[2];
    for (int j = 0; j < 2; j++) {
        idx r = j == 0 ? r_lo : r_hi;
        if (r < equal_lo) {
            picked[j] = lo;
        } else if (r < equal_lo + kept) {
            if (j == 1 && r_lo == r_hi)
                picked[j] = picked[0];
            else if (j == 1 && equal_lo <= r_lo)  /* work partitioned at r_lo: next one up */
                picked[j] = np_min(work + (r_lo - equal_lo + 1), kept - (r_lo - equal_lo + 1));
            else
                picked[j] = np_partition_at(work, kept, r - equal_lo);
        } else {
            picked[j] = hi;
        }
    }
    *out = k_lo == k_hi ? picked[0] : (picked[0] + picked[1]) / 2;
    return 0;
}

/* ------------------------------------------------------------- first differences */

enum { FORWARD = 0, INSIDE = 1, DEVIATION = 2, INSIDE_FORWARD = 3 };

static inline int valid(const double *x, const uint8_t *breaks, idx i, int mode)
{
    int inside = (mode == FORWARD) | !breaks[i];
    int forward = ((mode != FORWARD) & (mode != INSIDE_FORWARD)) | (x[i + 1] - x[i] > 0);
    return inside & forward;
}

static inline double value(const double *x, idx i, int mode, double centre)
{
    double d = x[i + 1] - x[i];
    return mode == DEVIATION ? fabs(d - centre) : d;
}

static idx count_valid(const double *x, const uint8_t *breaks, idx n, int mode)
{
    idx count = 0;
    for (idx i = 0; i < n; i++) count += valid(x, breaks, i, mode);
    return count;
}

/* the sample of difference_sample: returns how many were written to `sample` */
static idx sample_differences(const double *x, const uint8_t *breaks, idx n, int mode,
                              double centre, idx stride, double *sample)
{
    idx s = 0;
    for (idx i = 0; i < n; i += stride)
        if (valid(x, breaks, i, mode)) sample[s++] = value(x, i, mode, centre);
    return s;
}

/* one mode's loop: `mode` a constant in each call of bracket_differences, so the
 * selection compiles to selects (no branch) and the loop is specialised */
static inline __attribute__((always_inline)) void bracket_mode(
    const double *x, const uint8_t *breaks, idx n, const int mode, double centre, double lo,
    double hi, idx counts[4], double *inside)
{
    idx below = 0, equal_lo = 0, equal_hi = 0, kept = 0;
    const int distinct = hi != lo;
    for (idx i = 0; i < n; i++) {
        int ok = valid(x, breaks, i, mode);
        double v = value(x, i, mode, centre);
        below += ok & (v < lo);
        equal_lo += ok & (v == lo);
        equal_hi += ok & (v == hi) & distinct;
        inside[kept] = v;
        kept += ok & (lo < v) & (v < hi);
    }
    counts[0] = below;
    counts[1] = equal_lo;
    counts[2] = kept;
    counts[3] = equal_hi;
}

static void bracket_differences(const double *x, const uint8_t *breaks, idx n, int mode,
                                double centre, double lo, double hi, idx counts[4],
                                double *inside)
{
    switch (mode) {
    case FORWARD: bracket_mode(x, breaks, n, FORWARD, centre, lo, hi, counts, inside); break;
    case INSIDE: bracket_mode(x, breaks, n, INSIDE, centre, lo, hi, counts, inside); break;
    case DEVIATION: bracket_mode(x, breaks, n, DEVIATION, centre, lo, hi, counts, inside); break;
    default: bracket_mode(x, breaks, n, INSIDE_FORWARD, centre, lo, hi, counts, inside);
    }
}

static idx gather_differences(const double *x, const uint8_t *breaks, idx n, int mode,
                              double centre, idx count, double *out)
{
    idx k = 0;
    for (idx i = 0; i < n; i++)
        if (valid(x, breaks, i, mode)) {
            if (k < count) out[k] = value(x, i, mode, centre);
            k++;
        }
    return k;
}

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

/* ------------------------------------------------------------- the Python boundary */

enum { F64 = 'd', I64 = 'q', BOOL = '?' };

/* A C-contiguous 1-D buffer of `kind` (float64, int64 or bool), writable if asked;
 * TypeError naming the argument otherwise. */
static int take(PyObject *obj, Py_buffer *view, int kind, int writable, const char *name)
{
    int flags = PyBUF_C_CONTIGUOUS | PyBUF_FORMAT | (writable ? PyBUF_WRITABLE : 0);
    if (PyObject_GetBuffer(obj, view, flags) != 0) {
        PyErr_Clear();
        PyErr_Format(PyExc_TypeError, "%s must be a contiguous 1-D %s%s array", name,
                     kind == F64 ? "float64" : kind == I64 ? "int64" : "bool",
                     writable ? " (writable)" : "");
        return -1;
    }
    const char *f = view->format ? view->format : "B";
    if (*f == '@' || *f == '=' || *f == '<') f++;
    char c = f[0] && !f[1] ? f[0] : 0;
    int ok = view->ndim == 1 &&
             (kind == F64 ? c == 'd' && view->itemsize == 8
              : kind == I64 ? (c == 'q' || c == 'l') && view->itemsize == 8
                            : c == '?' && view->itemsize == 1);
    if (!ok) {
        PyBuffer_Release(view);
        PyErr_Format(PyExc_TypeError, "%s must be a contiguous 1-D %s array", name,
                     kind == F64 ? "float64" : kind == I64 ? "int64" : "bool");
        return -1;
    }
    return 0;
}

#define MAX_VIEWS 12
typedef struct {
    Py_buffer views[MAX_VIEWS];
    int count;
} Views;

/* The next argument's buffer (NULL after an error: the views taken so far released) */
static void *arg(Views *v, PyObject *obj, int kind, int writable, const char *name, idx *size)
{
    Py_buffer *view = &v->views[v->count];
    if (take(obj, view, kind, writable, name) != 0) {
        while (v->count > 0) PyBuffer_Release(&v->views[--v->count]);
        return NULL;
    }
    v->count++;
    *size = view->len / view->itemsize;
    return view->buf;
}

static PyObject *done(Views *v, PyObject *result)
{
    while (v->count > 0) PyBuffer_Release(&v->views[--v->count]);
    return result;
}

static PyObject *fail(Views *v, PyObject *type, const char *message)
{
    PyErr_SetString(type, message);
    return done(v, NULL);
}

/* x and breaks of the difference kernels: n = x.size - 1 differences, breaks >= n */
static int differences(Views *v, PyObject *x_obj, PyObject *b_obj, int mode,
                       const double **x, const uint8_t **breaks, idx *n)
{
    idx size, nb;
    if (!(*x = arg(v, x_obj, F64, 0, "x", &size))) return -1;
    if (!(*breaks = arg(v, b_obj, BOOL, 0, "breaks", &nb))) return -1;
    *n = size > 0 ? size - 1 : 0;
    if (nb < *n || mode < FORWARD || mode > INSIDE_FORWARD) {
        PyErr_SetString(PyExc_ValueError, "breaks needs x.size - 1 values and mode 0-3");
        done(v, NULL);
        return -1;
    }
    return 0;
}

static PyObject *py_median(PyObject *self, PyObject *args)
{
    PyObject *obj;
    Views v = {.count = 0};
    idx n;
    (void)self;
    if (!PyArg_ParseTuple(args, "O", &obj)) return NULL;
    const double *values = arg(&v, obj, F64, 0, "values", &n);
    if (!values) return NULL;
    double *work = malloc(sizeof(double) * (size_t)(n > 0 ? n : 1)), out = 0.0;
    int status = -1;
    if (work) {
        Py_BEGIN_ALLOW_THREADS
        status = long_median(values, n, work, &out);
        Py_END_ALLOW_THREADS
    }
    free(work);
    if (status != 0) return done(&v, PyErr_NoMemory());
    return done(&v, PyFloat_FromDouble(out));
}

static PyObject *py_difference_sample(PyObject *self, PyObject *args)
{
    PyObject *x_obj, *b_obj, *s_obj;
    int mode;
    double centre;
    Py_ssize_t stride;
    Views v = {.count = 0};
    const double *x;
    const uint8_t *breaks;
    idx n, size, count, s;
    (void)self;
    if (!PyArg_ParseTuple(args, "OOidnO", &x_obj, &b_obj, &mode, &centre, &stride, &s_obj))
        return NULL;
    if (differences(&v, x_obj, b_obj, mode, &x, &breaks, &n) != 0) return NULL;
    double *sample = arg(&v, s_obj, F64, 1, "sample", &size);
    if (!sample) return NULL;
    if (stride < 1 || size < n / stride + 1) return fail(&v, PyExc_ValueError,
                                                          "sample needs n // stride + 1 values");
    Py_BEGIN_ALLOW_THREADS
    count = count_valid(x, breaks, n, mode);
    s = sample_differences(x, breaks, n, mode, centre, stride, sample);
    Py_END_ALLOW_THREADS
    return done(&v, Py_BuildValue("nn", count, s));
}

static PyObject *py_bracket(PyObject *self, PyObject *args)
{
    PyObject *x_obj, *b_obj, *i_obj;
    int mode;
    double centre, lo, hi;
    Views v = {.count = 0};
    const double *x;
    const uint8_t *breaks;
    idx n, size, counts[4];
    (void)self;
    if (!PyArg_ParseTuple(args, "OOidddO", &x_obj, &b_obj, &mode, &centre, &lo, &hi, &i_obj))
        return NULL;
    if (differences(&v, x_obj, b_obj, mode, &x, &breaks, &n) != 0) return NULL;
    double *inside = arg(&v, i_obj, F64, 1, "inside", &size);
    if (!inside) return NULL;
    if (size < n) return fail(&v, PyExc_ValueError, "inside needs x.size - 1 values");
    Py_BEGIN_ALLOW_THREADS
    bracket_differences(x, breaks, n, mode, centre, lo, hi, counts, inside);
    Py_END_ALLOW_THREADS
    return done(&v, Py_BuildValue("nnnn", counts[0], counts[1], counts[2], counts[3]));
}

static PyObject *py_gather(PyObject *self, PyObject *args)
{
    PyObject *x_obj, *b_obj, *o_obj;
    int mode;
    double centre;
    Views v = {.count = 0};
    const double *x;
    const uint8_t *breaks;
    idx n, size, found;
    (void)self;
    if (!PyArg_ParseTuple(args, "OOidO", &x_obj, &b_obj, &mode, &centre, &o_obj)) return NULL;
    if (differences(&v, x_obj, b_obj, mode, &x, &breaks, &n) != 0) return NULL;
    double *out = arg(&v, o_obj, F64, 1, "out", &size);
    if (!out) return NULL;
    Py_BEGIN_ALLOW_THREADS
    found = gather_differences(x, breaks, n, mode, centre, size, out);
    Py_END_ALLOW_THREADS
    if (found != size) {
        PyErr_Format(PyExc_ValueError, "gather: %zd differences selected, out holds %zd",
                     found, size);
        return done(&v, NULL);
    }
    return done(&v, Py_NewRef(Py_None));
}

static PyObject *py_first_not_finite(PyObject *self, PyObject *args)
{
    PyObject *obj;
    Views v = {.count = 0};
    idx n, row = -1;
    (void)self;
    if (!PyArg_ParseTuple(args, "O", &obj)) return NULL;
    const double *values = arg(&v, obj, F64, 0, "values", &n);
    if (!values) return NULL;
    Py_BEGIN_ALLOW_THREADS
    for (idx i = 0; i < n; i++)
        if (!isfinite(values[i])) {
            row = i;
            break;
        }
    Py_END_ALLOW_THREADS
    return done(&v, PyLong_FromSsize_t(row));
}

/* find_breaks (out: bool) and steps_over (out: int64, returns how many) */
static PyObject *py_steps(PyObject *self, PyObject *args, int breaks)
{
    PyObject *t_obj, *o_obj;
    double limit;
    Views v = {.count = 0};
    idx n, size, kept = 0;
    (void)self;
    if (!PyArg_ParseTuple(args, "OdO", &t_obj, &limit, &o_obj)) return NULL;
    const double *t = arg(&v, t_obj, F64, 0, "time_s", &n);
    if (!t) return NULL;
    void *out = arg(&v, o_obj, breaks ? BOOL : I64, 1, "out", &size);
    if (!out) return NULL;
    if (size < (n > 1 ? n - 1 : 0)) return fail(&v, PyExc_ValueError,
                                                "out needs time_s.size - 1 values");
    Py_BEGIN_ALLOW_THREADS
    for (idx i = 0; i + 1 < n; i++) {
        double step = t[i + 1] - t[i];
        if (breaks) {
            ((uint8_t *)out)[i] = (step > limit) | (step <= 0);
        } else {
            ((int64_t *)out)[kept] = i;
            kept += step > limit;
        }
    }
    Py_END_ALLOW_THREADS
    return done(&v, PyLong_FromSsize_t(kept));
}

static PyObject *py_find_breaks(PyObject *self, PyObject *args) { return py_steps(self, args, 1); }
static PyObject *py_steps_over(PyObject *self, PyObject *args) { return py_steps(self, args, 0); }

static PyObject *py_segment_index(PyObject *self, PyObject *args)
{
    PyObject *b_obj, *o_obj;
    Views v = {.count = 0};
    idx n, size;
    (void)self;
    if (!PyArg_ParseTuple(args, "OO", &b_obj, &o_obj)) return NULL;
    const uint8_t *breaks = arg(&v, b_obj, BOOL, 0, "breaks", &n);
    if (!breaks) return NULL;
    int64_t *out = arg(&v, o_obj, I64, 1, "out", &size);
    if (!out) return NULL;
    if (size != n + 1) return fail(&v, PyExc_ValueError, "out needs breaks.size + 1 values");
    int64_t k = 0;
    out[0] = 0;
    for (idx i = 0; i < n; i++) {
        k += breaks[i] != 0;
        out[i + 1] = k;
    }
    return done(&v, Py_NewRef(Py_None));
}

static PyObject *py_segment_tests(PyObject *self, PyObject *args)
{
    PyObject *t_obj, *x_obj, *e_obj, *o_obj[4];
    Tests c;
    Views v = {.count = 0};
    idx m, nt, ne, size;
    uint8_t *out[4];
    static const char *names[4] = {"level", "variance", "clipped", "stepped"};
    (void)self;
    if (!PyArg_ParseTuple(args, "OOO(nnnddddddddnpp)OOOO", &t_obj, &x_obj, &e_obj,
                          &c.baseline_blocks, &c.var_rows, &c.min_run, &c.level_limit,
                          &c.diff_sigma, &c.diff_centre, &c.mad_to_sigma, &c.variance_limit,
                          &c.clip_limit, &c.high, &c.low, &c.clip_samples, &c.sigma_positive,
                          &c.held, &o_obj[0], &o_obj[1], &o_obj[2], &o_obj[3]))
        return NULL;
    const double *t = arg(&v, t_obj, F64, 0, "t", &nt);
    if (!t) return NULL;
    const double *values = arg(&v, x_obj, F64, 0, "values", &m);
    if (!values) return NULL;
    const idx *edges = arg(&v, e_obj, I64, 0, "edges", &ne);
    if (!edges) return NULL;
    for (int k = 0; k < 4; k++) {
        if (!(out[k] = arg(&v, o_obj[k], BOOL, 1, names[k], &size))) return NULL;
        if (size != m) return fail(&v, PyExc_ValueError, "each mask needs values.size values");
    }
    if (nt != m || m < 1) return fail(&v, PyExc_ValueError,
                                      "t and values need the same size, at least 1");
    int ordered = ne >= 2 && edges[0] == 0 && edges[ne - 1] == m;
    for (idx k = 0; ordered && k + 1 < ne; k++) ordered = edges[k] < edges[k + 1];
    if (!ordered) return fail(&v, PyExc_ValueError,
                              "edges must rise strictly from 0 to values.size");
    if (c.baseline_blocks < 1 || c.var_rows < 1 || c.min_run < 1 || c.clip_samples < 1)
        return fail(&v, PyExc_ValueError, "baseline_blocks, var_rows, min_run and "
                                          "clip_samples must be at least 1");
    int status;
    Py_BEGIN_ALLOW_THREADS
    status = segment_tests(t, values, m, edges, ne - 1, &c, out);
    Py_END_ALLOW_THREADS
    if (status != 0) return done(&v, PyErr_NoMemory());
    return done(&v, Py_NewRef(Py_None));
}

static PyObject *py_guard(PyObject *self, PyObject *args)
{
    PyObject *f_obj[4], *a_obj, *b_obj, *m_obj, *g_obj;
    Py_ssize_t after, before;
    Views v = {.count = 0};
    idx n, size, segments, stops_size;
    const uint8_t *found[4];
    static const char *names[4] = {"level", "variance", "clipped", "accel"};
    (void)self;
    if (!PyArg_ParseTuple(args, "OOOOOOnnOO", &f_obj[0], &f_obj[1], &f_obj[2], &f_obj[3],
                          &a_obj, &b_obj, &after, &before, &m_obj, &g_obj))
        return NULL;
    uint8_t *moving = arg(&v, m_obj, BOOL, 1, "moving", &n);
    if (!moving) return NULL;
    uint8_t *guarded = arg(&v, g_obj, BOOL, 1, "guarded", &size);
    if (!guarded) return NULL;
    if (size != n) return fail(&v, PyExc_ValueError, "guarded needs moving.size values");
    for (int k = 0; k < 4; k++) {
        if (!(found[k] = arg(&v, f_obj[k], BOOL, 0, names[k], &size))) return NULL;
        if (size != n) return fail(&v, PyExc_ValueError, "each mask needs moving.size values");
    }
    const idx *starts = arg(&v, a_obj, I64, 0, "starts", &segments);
    if (!starts) return NULL;
    const idx *stops = arg(&v, b_obj, I64, 0, "stops", &stops_size);
    if (!stops) return NULL;
    int ok = stops_size == segments && after >= 0 && before >= 0;
    for (idx k = 0; ok && k < segments; k++)
        ok = 0 <= starts[k] && starts[k] <= stops[k] && stops[k] <= n;
    if (!ok) return fail(&v, PyExc_ValueError, "starts and stops must be segments "
                                               "0 <= start <= stop <= n; after, before >= 0");
    Py_BEGIN_ALLOW_THREADS
    guard(found, starts, stops, segments, after, before, moving, guarded, n);
    Py_END_ALLOW_THREADS
    return done(&v, Py_NewRef(Py_None));
}

static PyObject *py_isolated_runs(PyObject *self, PyObject *args)
{
    PyObject *s_obj, *n_obj, *o_obj;
    Views v = {.count = 0};
    idx n, near_size, out_size;
    (void)self;
    if (!PyArg_ParseTuple(args, "OOO", &s_obj, &n_obj, &o_obj)) return NULL;
    const uint8_t *stepped = arg(&v, s_obj, BOOL, 0, "stepped", &n);
    if (!stepped) return NULL;
    const uint8_t *near = arg(&v, n_obj, BOOL, 0, "near", &near_size);
    if (!near) return NULL;
    uint8_t *out = arg(&v, o_obj, BOOL, 1, "out", &out_size);
    if (!out) return NULL;
    if (near_size != n || out_size != n)
        return fail(&v, PyExc_ValueError, "stepped, near and out need the same size");
    Py_BEGIN_ALLOW_THREADS
    isolated_runs(stepped, near, out, n);
    Py_END_ALLOW_THREADS
    return done(&v, Py_NewRef(Py_None));
}

/* ------------------------------------------------------------- the rows' digest */

/* A 64-bit digest of a column's bits, fed in pieces (compensate's check that its rows are
 * those the detector read, compensate/at_rest.py). The state: four lanes, word i going
 * into lane i % 4 by xxHash64's round (acc + w P2, rotated 31, times P1: for a fixed acc
 * a bijection of w, and for a fixed w of acc), and the count of words. So a change of one
 * word always changes the digest (each later step, the merge and the mixing are
 * bijections); more changes escape it with a chance of about 2^-64. The lanes are merged
 * by the same round, one after the other, and mixed by xxHash64's avalanche. */
#define P1 11400714785074694791ULL
#define P2 14029467366897019727ULL
#define P3 1609587929392839161ULL
#define P4 9650029242287828579ULL
#define P5 2870177450012600261ULL

static inline uint64_t rotl(uint64_t x, int r) { return (x << r) | (x >> (64 - r)); }
static inline uint64_t lane_round(uint64_t acc, uint64_t w) { return rotl(acc + w * P2, 31) * P1; }

static void digest_feed(uint64_t state[5], const uint64_t *words, idx n)
{
    uint64_t lane[4] = {state[0], state[1], state[2], state[3]};
    idx i = 0;
    uint64_t first = state[4] & 3;
    for (; i < n && ((first + (uint64_t)i) & 3); i++)  /* up to a stripe's start */
        lane[(first + (uint64_t)i) & 3] = lane_round(lane[(first + (uint64_t)i) & 3], words[i]);
    for (; i + 4 <= n; i += 4)
        for (int k = 0; k < 4; k++) lane[k] = lane_round(lane[k], words[i + k]);
    for (; i < n; i++) lane[(first + (uint64_t)i) & 3] = lane_round(lane[(first + (uint64_t)i) & 3],
                                                                words[i]);
    for (int k = 0; k < 4; k++) state[k] = lane[k];
    state[4] += (uint64_t)n;
}

static uint64_t digest_final(const uint64_t state[5])
{
    uint64_t h = P5;  /* the lanes in turn: each step a bijection of the lane and of h */
    for (int k = 0; k < 4; k++) h = lane_round(h, state[k]) + P4;
    h += state[4] * P5;
    h ^= h >> 33;
    h *= P2;
    h ^= h >> 29;
    h *= P3;
    h ^= h >> 32;
    return h;
}

static PyObject *py_digest_update(PyObject *self, PyObject *args)
{
    PyObject *s_obj, *v_obj;
    Views v = {.count = 0};
    idx ns, n;
    (void)self;
    if (!PyArg_ParseTuple(args, "OO", &s_obj, &v_obj)) return NULL;
    int64_t *state = arg(&v, s_obj, I64, 1, "state", &ns);
    if (!state) return NULL;
    const double *values = arg(&v, v_obj, F64, 0, "values", &n);
    if (!values) return NULL;
    if (ns != 5) return fail(&v, PyExc_ValueError, "state needs 5 int64 values");
    Py_BEGIN_ALLOW_THREADS
    digest_feed((uint64_t *)state, (const uint64_t *)values, n);
    Py_END_ALLOW_THREADS
    return done(&v, Py_NewRef(Py_None));
}

static PyObject *py_digest(PyObject *self, PyObject *args)
{
    PyObject *s_obj;
    Views v = {.count = 0};
    idx ns;
    (void)self;
    if (!PyArg_ParseTuple(args, "O", &s_obj)) return NULL;
    int64_t *state = arg(&v, s_obj, I64, 0, "state", &ns);
    if (!state) return NULL;
    if (ns != 5) return fail(&v, PyExc_ValueError, "state needs 5 int64 values");
    return done(&v, PyLong_FromUnsignedLongLong(digest_final((const uint64_t *)state)));
}

static PyMethodDef methods[] = {
    {"median", py_median, METH_VARARGS, "median(values) -> float (see _motion_kernel.median)"},
    {"difference_sample", py_difference_sample, METH_VARARGS,
     "difference_sample(x, breaks, mode, centre, stride, sample) -> (count, written)"},
    {"bracket", py_bracket, METH_VARARGS,
     "bracket(x, breaks, mode, centre, lo, hi, inside) -> (below, equal_lo, kept, equal_hi)"},
    {"gather", py_gather, METH_VARARGS, "gather(x, breaks, mode, centre, out) -> None"},
    {"first_not_finite", py_first_not_finite, METH_VARARGS, "first_not_finite(values) -> int"},
    {"find_breaks", py_find_breaks, METH_VARARGS, "find_breaks(time_s, gap_s, out) -> int"},
    {"steps_over", py_steps_over, METH_VARARGS, "steps_over(time_s, limit, out) -> kept"},
    {"segment_index", py_segment_index, METH_VARARGS, "segment_index(breaks, out) -> None"},
    {"segment_tests", py_segment_tests, METH_VARARGS,
     "segment_tests(t, values, edges, tests, level, variance, clipped, stepped) -> None"},
    {"guard", py_guard, METH_VARARGS,
     "guard(level, variance, clipped, accel, starts, stops, after, before, moving, "
     "guarded) -> None"},
    {"isolated_runs", py_isolated_runs, METH_VARARGS, "isolated_runs(stepped, near, out)"},
    {"digest_update", py_digest_update, METH_VARARGS,
     "digest_update(state, values): feed float64 values' bits into a digest state (5 int64)"},
    {"digest", py_digest, METH_VARARGS, "digest(state) -> int: the 64-bit digest so far"},
    {NULL, NULL, 0, NULL},
};

static struct PyModuleDef module = {
    PyModuleDef_HEAD_INIT, "_motion_native",
    "The at-rest detector's loops (see _motion_native.c).", -1, methods,
    NULL, NULL, NULL, NULL,
};

PyMODINIT_FUNC PyInit__motion_native(void) { return PyModule_Create(&module); }
