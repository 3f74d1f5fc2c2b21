/* The boundary of hrgtc's compiled kernels (_spike_native.c, _rate_native.c,
 * _plateau_native.c, _extended_native.c): numpy arrays taken through the buffer protocol,
 * their type, dimension, contiguity and length checked before a loop reads them.
 *
 * A wrong array raises TypeError (dtype, dimension, layout) or ValueError (length) naming
 * the argument; nothing is converted or copied here (the Python side of each kernel does
 * that where a caller may pass another dtype).
 */
#ifndef HRGTC_BUFFERS_H
#define HRGTC_BUFFERS_H

#define PY_SSIZE_T_CLEAN
#include <Python.h>
#include <string.h>

/* The struct format of a buffer, without a byte-order or alignment prefix ('@', '=', '<'). */
static inline const char *hrgtc_format(const Py_buffer *view)
{
    const char *f = view->format ? view->format : "B";
    while (*f == '@' || *f == '=' || *f == '<') f++;
    return f;
}

/* Is the format `f` one of `kinds` (a string of struct codes) with this item size? */
static inline int hrgtc_kind(const Py_buffer *view, const char *kinds, Py_ssize_t itemsize)
{
    const char *f = hrgtc_format(view);
    return f[0] != '\0' && f[1] == '\0' && strchr(kinds, f[0]) != NULL &&
           view->itemsize == itemsize;
}

/* A C-contiguous 1-D buffer of `kinds` items of `itemsize` bytes (writable if asked) into
 * `view`; 0 on success, -1 with the exception set (and `view` released). `what` names the
 * argument and its dtype in the message ("time_s (float64)"). */
static inline int hrgtc_vector(PyObject *obj, Py_buffer *view, const char *kinds,
                               Py_ssize_t itemsize, int writable, const char *what)
{
    int flags = PyBUF_C_CONTIGUOUS | PyBUF_FORMAT | (writable ? PyBUF_WRITABLE : 0);
    if (PyObject_GetBuffer(obj, view, flags) != 0) {
        PyErr_Clear();
        PyErr_Format(PyExc_TypeError, "%s must be a %scontiguous 1-D numpy array", what,
                     writable ? "writable, " : "");
        return -1;
    }
    if (view->ndim != 1 || !hrgtc_kind(view, kinds, itemsize)) {
        PyErr_Format(PyExc_TypeError, "%s must be a contiguous 1-D numpy array, got %d-D "
                     "of format '%s'", what, view->ndim, hrgtc_format(view));
        PyBuffer_Release(view);
        return -1;
    }
    return 0;
}

/* Items in a 1-D buffer. */
static inline Py_ssize_t hrgtc_len(const Py_buffer *view)
{
    return view->len / view->itemsize;
}

/* Release the first `count` of `views` (those taken so far). */
static inline void hrgtc_release(Py_buffer *views, int count)
{
    for (int i = 0; i < count; i++) PyBuffer_Release(&views[i]);
}

#define HRGTC_F64 "d"
#define HRGTC_BOOL "?bB"  /* numpy bool, int8, uint8: one byte, 0 or not */

#endif
