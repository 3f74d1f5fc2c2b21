/* The soak plateaus' block statistics (hrgtc.thermometry.plateaus), one pass each.
 *
 * Private to hrgtc.thermometry._plateau_kernel (its Python side); built by
 * `pip install -e .` (setup.py). Why C and not numba: `calibrate` paid numba's import,
 * its first-call start and the loading of two cached kernels for passes of tens of ms
 * (docs/architecture.md, "The native kernels").
 *
 * block_index: numpy.floor_divide(t - t[0], block_s).astype(intp) of increasing finite
 * times, by floor(d / block_s) where the rounded quotient is not within NEAR of an integer
 * (rounding is monotonic and integers are representable, so there both are the exact
 * quotient's floor) and by numpy's own npy_divmod where it is. block_sums: per block, the
 * count and the sums of the time, of the frequency less a reference, of its square and of
 * the chamber temperature, added in the order of the samples as numpy.bincount adds its
 * weights. Both are the numba kernels they replace bit for bit (tests/thermometry/
 * test_plateau_native.py); -ffp-contract=off (setup.py): no product is fused into an add.
 */
#include "../_buffers.h"
#include <math.h>
#include <stdint.h>

/* A quotient this close to an integer (relative) takes numpy's own floor division. */
#define NEAR 1e-9

/* numpy.floor_divide(a, b) for a finite a and b != 0: numpy's npy_divmod (the exact
 * fmod, then the quotient rounded to its integer). */
static double floor_divide(double a, double b)
{
    double mod = fmod(a, b);
    double div = (a - mod) / b;
    if (mod != 0.0 && (b < 0.0) != (mod < 0.0)) div -= 1.0;
    if (div != 0.0) {
        double whole = floor(div);
        if (div - whole > 0.5) whole += 1.0;
        return whole;
    }
    return copysign(0.0, a / b);
}

static void block_index(const double *t, long n, double block_s, int64_t *out)
{
    if (!n) return;
    const double origin = t[0];
    for (long i = 0; i < n; i++) {
        double a = t[i] - origin;
        double quotient = a / block_s;
        double whole = floor(quotient);
        double guard = NEAR * (1.0 + fabs(quotient));
        if (quotient - whole > guard && whole + 1.0 - quotient > guard)
            out[i] = (int64_t)whole;
        else
            out[i] = (int64_t)floor_divide(a, block_s);
    }
}

/* The arrays of block_sums: the block of each sample, the samples' time, frequency and
 * chamber temperature; the per-block count and sums. */
enum { BLOCK, TIME, FREQ, CHAMBER, COUNT, TIME_SUM, DEV_SUM, DEV_SQ_SUM, CHAMBER_SUM, ARRAYS };

/* -1 (nothing summed past it) at the first sample whose block is outside [0, bins). */
static long block_sums(const int64_t *block, const double *time_s, const double *freq_hz,
                       double ref_hz, const double *chamber_c, long n, long bins,
                       int64_t *count, double *time_sum, double *dev_sum, double *dev_sq_sum,
                       double *chamber_sum)
{
    for (long i = 0; i < n; i++) {
        int64_t k = block[i];
        if (k < 0 || k >= bins) return i;
        double dev = freq_hz[i] - ref_hz;
        count[k] += 1;
        time_sum[k] += time_s[i];
        dev_sum[k] += dev;
        dev_sq_sum[k] += dev * dev;
        chamber_sum[k] += chamber_c[i];
    }
    return -1;
}

#define INT64 "lq"

static PyObject *py_floor_divide(PyObject *self, PyObject *args)
{
    double a, b;
    (void)self;
    if (!PyArg_ParseTuple(args, "dd", &a, &b)) return NULL;
    return PyFloat_FromDouble(floor_divide(a, b));
}

static PyObject *py_block_index(PyObject *self, PyObject *args)
{
    PyObject *objects[2];
    double block_s;
    (void)self;
    if (!PyArg_ParseTuple(args, "OdO", &objects[0], &block_s, &objects[1])) return NULL;
    Py_buffer views[2];
    if (hrgtc_vector(objects[0], &views[0], HRGTC_F64, 8, 0, "time_s (float64)")) return NULL;
    if (hrgtc_vector(objects[1], &views[1], INT64, 8, 1, "out (intp)")) {
        hrgtc_release(views, 1);
        return NULL;
    }
    long n = (long)hrgtc_len(&views[0]);
    if (hrgtc_len(&views[1]) != n) {
        PyErr_Format(PyExc_ValueError, "out has %zd items for %ld times",
                     hrgtc_len(&views[1]), n);
        hrgtc_release(views, 2);
        return NULL;
    }
    Py_BEGIN_ALLOW_THREADS
    block_index(views[0].buf, n, block_s, views[1].buf);
    Py_END_ALLOW_THREADS
    hrgtc_release(views, 2);
    Py_RETURN_NONE;
}

static int take_sums(PyObject **objects, Py_buffer *views)
{
    static const char *const names[ARRAYS] = {
        "block (intp)", "time_s (float64)", "freq_hz (float64)", "chamber_c (float64)",
        "count (int64)", "time_sum (float64)", "dev_sum (float64)", "dev_sq_sum (float64)",
        "chamber_sum (float64)"};
    for (int i = 0; i < ARRAYS; i++) {
        const char *kinds = i == BLOCK || i == COUNT ? INT64 : HRGTC_F64;
        if (hrgtc_vector(objects[i], &views[i], kinds, 8, i >= COUNT, names[i])) {
            hrgtc_release(views, i);
            return -1;
        }
    }
    for (int i = 1; i < ARRAYS; i++) {
        int input = i < COUNT;
        Py_ssize_t want = hrgtc_len(&views[input ? BLOCK : COUNT]);
        if (hrgtc_len(&views[i]) != want) {
            PyErr_Format(PyExc_ValueError, "%s has %zd items, not the %zd of %s", names[i],
                         hrgtc_len(&views[i]), want, input ? "block" : "count");
            hrgtc_release(views, ARRAYS);
            return -1;
        }
    }
    return 0;
}

static PyObject *py_block_sums(PyObject *self, PyObject *args)
{
    PyObject *objects[ARRAYS];
    double ref_hz;
    (void)self;
    if (!PyArg_ParseTuple(args, "OOOdOOOOOO", &objects[BLOCK], &objects[TIME], &objects[FREQ],
                          &ref_hz, &objects[CHAMBER], &objects[COUNT], &objects[TIME_SUM],
                          &objects[DEV_SUM], &objects[DEV_SQ_SUM], &objects[CHAMBER_SUM]))
        return NULL;
    Py_buffer views[ARRAYS];
    if (take_sums(objects, views)) return NULL;
    long bad;
    Py_BEGIN_ALLOW_THREADS
    bad = block_sums(views[BLOCK].buf, views[TIME].buf, views[FREQ].buf, ref_hz,
                     views[CHAMBER].buf, (long)hrgtc_len(&views[BLOCK]),
                     (long)hrgtc_len(&views[COUNT]), views[COUNT].buf, views[TIME_SUM].buf,
                     views[DEV_SUM].buf, views[DEV_SQ_SUM].buf, views[CHAMBER_SUM].buf);
    Py_END_ALLOW_THREADS
    if (bad >= 0)
        PyErr_Format(PyExc_ValueError, "block[%ld] = %lld is not a block of 0 to %zd", bad,
                     (long long)((const int64_t *)views[BLOCK].buf)[bad],
                     hrgtc_len(&views[COUNT]) - 1);
    hrgtc_release(views, ARRAYS);
    if (bad >= 0) return NULL;
    Py_RETURN_NONE;
}

static PyMethodDef methods[] = {
    {"floor_divide", py_floor_divide, METH_VARARGS,
     "floor_divide(a, b) -> float: numpy.floor_divide of finite a and b != 0."},
    {"block_index", py_block_index, METH_VARARGS,
     "block_index(time_s, block_s, out) -> None\n\n"
     "floor_divide(time_s - time_s[0], block_s) into out (intp, of time_s's length)."},
    {"block_sums", py_block_sums, METH_VARARGS,
     "block_sums(block, time_s, freq_hz, ref_hz, chamber_c, count, time_sum, dev_sum,\n"
     "           dev_sq_sum, chamber_sum) -> None\n\n"
     "Per block (0 <= block < len(count)): adds the count and the sums to the zeroed\n"
     "outputs, in the order of the samples."},
    {NULL, NULL, 0, NULL},
};

static struct PyModuleDef module = {
    PyModuleDef_HEAD_INIT, "_plateau_native",
    "The soak plateaus' block statistics (see _plateau_native.c).", -1, methods,
    NULL, NULL, NULL, NULL,
};

PyMODINIT_FUNC PyInit__plateau_native(void) { return PyModule_Create(&module); }
