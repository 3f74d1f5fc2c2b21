/* numba's order statistics (np.median, np.sort, np.partition, np.min) and the at-rest
 * detector's bracketing median built on them.
 *
 * Part of _motion_native.c, which includes it once (one translation unit: the functions
 * are static). */
#ifndef HRGTC_MOTION_ORDER_H
#define HRGTC_MOTION_ORDER_H

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


#endif /* HRGTC_MOTION_ORDER_H */
