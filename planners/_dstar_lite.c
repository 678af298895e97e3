/* D* Lite of planners/dstar_lite_reference.py DStarLiteReference, compiled: the same keys, expansions, g, rhs and
 * paths.
 *
 * Search(occupied, rows, cols, start, goal, diagonal_extra, costs, penalty) keeps the search's state in C arrays:
 * g, rhs, each vertex's open-list key (the reference's ``open`` dict), the heap of (k1, k2, vertex) entries with
 * the reference's lazy deletion (an entry counts while it equals its vertex's key), the cells' occupancy, the
 * legal-move masks (planners/grid_graph.py move_masks' rule: 8-connected, no corner cutting) and the optional cell
 * penalties.  The heap is ordered by (k1, k2, vertex), the reference's heapq tuples: equal entries are the same
 * tuple, so any correct priority queue pops the same sequence.  Keys, rhs minima and move costs are the same double
 * operations in the same order (a move costs costs[k], or costs[k] * (1 + 0.5 * (p_u + p_v)) with penalties; the
 * heuristic is diagonal_extra x the int min plus the int max, as grid_graph.octile_cells), built with
 * -ffp-contract=off (no fused multiply-add), so every comparison, hence every tie, goes the same way.
 *
 * Methods: compute(start, km) -> expansions of this call; path(start) -> flat cells to the goal or None (the cost
 * field cannot be followed); update_cells(indices int64, occupied uint8, start, km); update_penalty(penalty float64,
 * start, km) -> changed cells; rhs_at(v); values() -> (g list, rhs list); masks() -> bytes.
 */
#define PY_SSIZE_T_CLEAN
#include <Python.h>
#include <stdint.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>

typedef struct {
    double k1, k2;
    int64_t v;
} Entry;

static int less(const Entry *a, const Entry *b) {
    if (a->k1 != b->k1)
        return a->k1 < b->k1;
    if (a->k2 != b->k2)
        return a->k2 < b->k2;
    return a->v < b->v;
}

typedef struct {
    Entry *items;
    Py_ssize_t size, capacity;
} Heap;

static int heap_push(Heap *h, double k1, double k2, int64_t v) {
    if (h->size == h->capacity) {
        Py_ssize_t capacity = h->capacity ? 2 * h->capacity : 1024;
        Entry *items = realloc(h->items, (size_t)capacity * sizeof(Entry));
        if (!items)
            return 0;
        h->items = items;
        h->capacity = capacity;
    }
    Entry e = {k1, k2, v};
    Py_ssize_t i = h->size++;
    while (i > 0) {
        Py_ssize_t up = (i - 1) / 2;
        if (!less(&e, &h->items[up]))
            break;
        h->items[i] = h->items[up];
        i = up;
    }
    h->items[i] = e;
    return 1;
}

static void heap_pop(Heap *h) {
    Entry last = h->items[--h->size];
    Py_ssize_t i = 0;
    for (;;) {
        Py_ssize_t child = 2 * i + 1;
        if (child >= h->size)
            break;
        if (child + 1 < h->size && less(&h->items[child + 1], &h->items[child]))
            child++;
        if (!less(&h->items[child], &last))
            break;
        h->items[i] = h->items[child];
        i = child;
    }
    if (h->size)
        h->items[i] = last;
}

/* (d_row, d_col) of the 8 moves, planners/grid_graph.py DIRECTIONS: 4 orthogonal first, then 4 diagonal. */
static const int DR[8] = {-1, 1, 0, 0, -1, -1, 1, 1};
static const int DC[8] = {0, 0, -1, 1, -1, 1, -1, 1};

typedef struct {
    PyObject_HEAD
    Py_ssize_t rows, cols, n;
    int64_t goal, offsets[8];
    double diagonal_extra, costs[8];
    double *g, *rhs, *key1, *key2, *penalty; /* penalty NULL: none */
    unsigned char *open, *occupied, *masks, *touched;
    Heap heap;
    Py_ssize_t expansions;
    /* the current start and key modifier, set by each call */
    int64_t start_row, start_col;
    double km;
} Search;

static double heuristic(const Search *s, int64_t v) {
    int64_t dr = v / s->cols - s->start_row, dc = v % s->cols - s->start_col;
    if (dr < 0)
        dr = -dr;
    if (dc < 0)
        dc = -dc;
    return s->diagonal_extra * (double)(dr < dc ? dr : dc) + (double)(dr > dc ? dr : dc);
}

static double move_cost(const Search *s, int64_t u, int k, int64_t v) {
    if (!s->penalty)
        return s->costs[k];
    return s->costs[k] * (1.0 + 0.5 * (s->penalty[u] + s->penalty[v]));
}

/* min over the moves out of v of c + g (INF with none). */
static double min_rhs(const Search *s, int64_t v) {
    double best = INFINITY;
    const unsigned mask = s->masks[v];
    for (int k = 0; k < 8; k++) {
        if (!(mask >> k & 1))
            continue;
        const int64_t q = v + s->offsets[k];
        const double c = move_cost(s, v, k, q) + s->g[q];
        if (c < best)
            best = c;
    }
    return best;
}

/* UpdateVertex: queue v with its key when inconsistent, else drop it from the open list. 0: out of memory. */
static int update_vertex(Search *s, int64_t v) {
    const double gv = s->g[v], rv = s->rhs[v];
    if (gv != rv) {
        const double m = gv < rv ? gv : rv;
        const double k1 = m + heuristic(s, v) + s->km;
        s->key1[v] = k1;
        s->key2[v] = m;
        s->open[v] = 1;
        return heap_push(&s->heap, k1, m, v);
    }
    s->open[v] = 0;
    return 1;
}

/* The legal-move mask of cell v (move_masks' rule; cells beyond the grid are blocked). */
static unsigned cell_mask(const Search *s, int64_t v) {
    if (s->occupied[v])
        return 0;
    const int64_t r = v / s->cols, c = v % s->cols;
    unsigned mask = 0;
    for (int k = 0; k < 8; k++) {
        const int64_t rr = r + DR[k], cc = c + DC[k];
        if (rr < 0 || rr >= s->rows || cc < 0 || cc >= s->cols || s->occupied[rr * s->cols + cc])
            continue;
        if (k >= 4 && (s->occupied[rr * s->cols + c] || s->occupied[r * s->cols + cc]))
            continue;
        mask |= 1u << k;
    }
    return mask;
}

static int set_start(Search *s, Py_ssize_t start, double km) {
    if (start < 0 || start >= s->n) {
        PyErr_SetString(PyExc_ValueError, "start cell outside the grid");
        return 0;
    }
    s->start_row = start / s->cols;
    s->start_col = start % s->cols;
    s->km = km;
    return 1;
}

/* Mark v and its in-grid 8 neighbours as touched; widen [lo, hi]. */
static void touch_block(Search *s, int64_t v, int64_t *lo, int64_t *hi) {
    const int64_t r = v / s->cols, c = v % s->cols;
    for (int64_t rr = r - 1; rr <= r + 1; rr++) {
        if (rr < 0 || rr >= s->rows)
            continue;
        for (int64_t cc = c - 1; cc <= c + 1; cc++) {
            if (cc < 0 || cc >= s->cols)
                continue;
            const int64_t w = rr * s->cols + cc;
            s->touched[w] = 1;
            if (w < *lo)
                *lo = w;
            if (w > *hi)
                *hi = w;
        }
    }
}

/* The reference's _repair over the touched vertices in ascending order (and clears the marks). 0: out of memory. */
static int repair(Search *s, int64_t lo, int64_t hi) {
    int ok = 1;
    for (int64_t v = lo; v <= hi; v++) {
        if (!s->touched[v])
            continue;
        s->touched[v] = 0;
        if (!ok)
            continue;
        if (s->occupied[v])
            s->g[v] = INFINITY;
        if (v != s->goal)
            s->rhs[v] = min_rhs(s, v);
        ok = update_vertex(s, v);
    }
    return ok;
}

static void Search_dealloc(Search *s) {
    free(s->g);
    free(s->rhs);
    free(s->key1);
    free(s->key2);
    free(s->penalty);
    free(s->open);
    free(s->occupied);
    free(s->masks);
    free(s->touched);
    free(s->heap.items);
    Py_TYPE(s)->tp_free((PyObject *)s);
}

static int Search_init(Search *s, PyObject *args, PyObject *Py_UNUSED(kwds)) {
    Py_buffer b_occ, b_costs, b_pen = {0};
    Py_ssize_t rows, cols, start, goal;
    double diagonal_extra;
    PyObject *penalty;
    if (!PyArg_ParseTuple(args, "y*nnnndy*O", &b_occ, &rows, &cols, &start, &goal, &diagonal_extra, &b_costs,
                          &penalty))
        return -1;
    int result = -1;
    const int has_penalty = penalty != Py_None;
    if (has_penalty && PyObject_GetBuffer(penalty, &b_pen, PyBUF_SIMPLE) < 0)
        goto done;
    if (s->g) {
        PyErr_SetString(PyExc_RuntimeError, "Search is initialised once");
        goto done;
    }
    const Py_ssize_t n = rows * cols;
    if (rows < 1 || cols < 1 || b_occ.len != n || b_costs.len != 8 * (Py_ssize_t)sizeof(double) || start < 0
        || start >= n || goal < 0 || goal >= n || (has_penalty && b_pen.len != n * (Py_ssize_t)sizeof(double))) {
        PyErr_SetString(PyExc_ValueError, "Search: occupied (one byte per cell of a rows x cols grid), start and goal "
                        "cells, 8 move costs, penalty (a float64 per cell) or None");
        goto done;
    }
    s->rows = rows;
    s->cols = cols;
    s->n = n;
    s->goal = goal;
    s->diagonal_extra = diagonal_extra;
    memcpy(s->costs, b_costs.buf, sizeof s->costs);
    for (int k = 0; k < 8; k++)
        s->offsets[k] = (int64_t)DR[k] * cols + DC[k];
    s->g = malloc((size_t)n * sizeof(double));
    s->rhs = malloc((size_t)n * sizeof(double));
    s->key1 = malloc((size_t)n * sizeof(double));
    s->key2 = malloc((size_t)n * sizeof(double));
    s->open = calloc((size_t)n, 1);
    s->occupied = malloc((size_t)n);
    s->masks = malloc((size_t)n);
    s->touched = calloc((size_t)n, 1);
    if (has_penalty)
        s->penalty = malloc((size_t)n * sizeof(double));
    if (!s->g || !s->rhs || !s->key1 || !s->key2 || !s->open || !s->occupied || !s->masks || !s->touched
        || (has_penalty && !s->penalty)) {
        PyErr_NoMemory();
        goto done;
    }
    const unsigned char *occ = b_occ.buf;
    for (Py_ssize_t i = 0; i < n; i++) {
        s->g[i] = s->rhs[i] = INFINITY;
        s->occupied[i] = occ[i] != 0;
    }
    for (Py_ssize_t i = 0; i < n; i++)
        s->masks[i] = (unsigned char)cell_mask(s, i);
    if (has_penalty)
        memcpy(s->penalty, b_pen.buf, (size_t)n * sizeof(double));
    set_start(s, start, 0.0);
    s->rhs[goal] = 0.0;
    if (!update_vertex(s, goal)) {
        PyErr_NoMemory();
        goto done;
    }
    result = 0;
done:
    PyBuffer_Release(&b_occ);
    PyBuffer_Release(&b_costs);
    if (b_pen.obj)
        PyBuffer_Release(&b_pen);
    return result;
}

static int ready(Search *s) {
    if (!s->g) {
        PyErr_SetString(PyExc_RuntimeError, "Search is not initialised");
        return 0;
    }
    return 1;
}

/* ComputeShortestPath (the reference's compute_shortest_path, step for step). */
static PyObject *Search_compute(Search *s, PyObject *args) {
    Py_ssize_t start;
    double km;
    if (!PyArg_ParseTuple(args, "nd", &start, &km) || !ready(s) || !set_start(s, start, km))
        return NULL;
    const int64_t st = start, goal = s->goal;
    double *g = s->g, *rhs = s->rhs;
    Heap *heap = &s->heap;
    Py_ssize_t expansions = 0;
    int ok = 1;
    while (ok) {
        double k1 = 0.0, k2 = 0.0;
        int64_t u = -1;
        while (heap->size) { /* TopKey, skipping stale entries */
            const Entry *top = &heap->items[0];
            if (s->open[top->v] && s->key1[top->v] == top->k1 && s->key2[top->v] == top->k2) {
                k1 = top->k1;
                k2 = top->k2;
                u = top->v;
                break;
            }
            heap_pop(heap);
        }
        if (u < 0)
            break;
        double m = g[st] < rhs[st] ? g[st] : rhs[st];
        const double s1 = m + heuristic(s, st) + s->km + 1e-9, s2 = m + 1e-9;
        const int before = k1 != s1 ? k1 < s1 : k2 < s2;
        if (!(before || rhs[st] != g[st]))
            break;
        m = g[u] < rhs[u] ? g[u] : rhs[u];
        const double n1 = m + heuristic(s, u) + s->km; /* CalculateKey */
        expansions++;
        if (k1 != n1 ? k1 < n1 : k2 < m) {
            s->key1[u] = n1;
            s->key2[u] = m;
            ok = heap_push(heap, n1, m, u);
        } else if (g[u] > rhs[u]) {
            const double gu = g[u] = rhs[u];
            s->open[u] = 0;
            heap_pop(heap);
            const unsigned mask = s->masks[u];
            for (int k = 0; k < 8 && ok; k++) {
                if (!(mask >> k & 1))
                    continue;
                const int64_t p = u + s->offsets[k];
                const double w = move_cost(s, u, k, p);
                if (p != goal && rhs[p] > w + gu)
                    rhs[p] = w + gu;
                ok = update_vertex(s, p);
            }
        } else {
            const double g_old = g[u];
            g[u] = INFINITY;
            const unsigned mask = s->masks[u];
            for (int k = 0; k < 9 && ok; k++) { /* the moves out of u, then u itself */
                if (k < 8 && !(mask >> k & 1))
                    continue;
                const int64_t p = k < 8 ? u + s->offsets[k] : u;
                if (p != goal && (k == 8 || rhs[p] == move_cost(s, u, k, p) + g_old))
                    rhs[p] = min_rhs(s, p);
                ok = update_vertex(s, p);
            }
        }
    }
    s->expansions += expansions;
    if (!ok)
        return PyErr_NoMemory();
    return PyLong_FromSsize_t(expansions);
}

/* Cells from start to the goal following the smallest c + g (the first such move in DIRECTIONS order); None when
 * a vertex has no move or the walk outgrows the grid. */
static PyObject *Search_path(Search *s, PyObject *args) {
    Py_ssize_t start;
    if (!PyArg_ParseTuple(args, "n", &start) || !ready(s))
        return NULL;
    if (start < 0 || start >= s->n) {
        PyErr_SetString(PyExc_ValueError, "start cell outside the grid");
        return NULL;
    }
    PyObject *cells = PyList_New(0);
    if (!cells)
        return NULL;
    int64_t cur = start;
    Py_ssize_t count = 1;
    for (;;) {
        PyObject *cell = PyLong_FromLongLong(cur);
        if (!cell || PyList_Append(cells, cell) < 0) {
            Py_XDECREF(cell);
            Py_DECREF(cells);
            return NULL;
        }
        Py_DECREF(cell);
        if (cur == s->goal)
            return cells;
        double best = INFINITY;
        int64_t next = -1;
        const unsigned mask = s->masks[cur];
        for (int k = 0; k < 8; k++) {
            if (!(mask >> k & 1))
                continue;
            const int64_t v = cur + s->offsets[k];
            const double c = move_cost(s, cur, k, v) + s->g[v];
            if (c < best) {
                best = c;
                next = v;
            }
        }
        if (next < 0 || count > s->n) {
            Py_DECREF(cells);
            Py_RETURN_NONE;
        }
        cur = next;
        count++;
    }
}

static PyObject *Search_update_cells(Search *s, PyObject *args) {
    Py_buffer b_idx, b_occ;
    Py_ssize_t start;
    double km;
    if (!PyArg_ParseTuple(args, "y*y*nd", &b_idx, &b_occ, &start, &km))
        return NULL;
    PyObject *result = NULL;
    if (!ready(s) || !set_start(s, start, km))
        goto done;
    const Py_ssize_t count = b_idx.len / (Py_ssize_t)sizeof(int64_t);
    const int64_t *idx = b_idx.buf;
    const unsigned char *occ = b_occ.buf;
    if (b_idx.len % (Py_ssize_t)sizeof(int64_t) || b_occ.len != count) {
        PyErr_SetString(PyExc_ValueError, "update_cells: int64 cells and one occupied byte each");
        goto done;
    }
    for (Py_ssize_t i = 0; i < count; i++) {
        if (idx[i] < 0 || idx[i] >= s->n) {
            PyErr_SetString(PyExc_ValueError, "update_cells: a cell outside the grid");
            goto done;
        }
    }
    for (Py_ssize_t i = 0; i < count; i++)
        s->occupied[idx[i]] = occ[i] != 0;
    int64_t lo = s->n, hi = -1;
    for (Py_ssize_t i = 0; i < count; i++)
        touch_block(s, idx[i], &lo, &hi);
    for (int64_t v = lo; v <= hi; v++) /* a mask depends on its cell's 3 x 3 block */
        if (s->touched[v])
            s->masks[v] = (unsigned char)cell_mask(s, v);
    if (!repair(s, lo, hi)) {
        PyErr_NoMemory();
        goto done;
    }
    result = Py_NewRef(Py_None);
done:
    PyBuffer_Release(&b_idx);
    PyBuffer_Release(&b_occ);
    return result;
}

static PyObject *Search_update_penalty(Search *s, PyObject *args) {
    Py_buffer b_pen;
    Py_ssize_t start;
    double km;
    if (!PyArg_ParseTuple(args, "y*nd", &b_pen, &start, &km))
        return NULL;
    PyObject *result = NULL;
    if (!ready(s) || !set_start(s, start, km))
        goto done;
    if (b_pen.len != s->n * (Py_ssize_t)sizeof(double)) {
        PyErr_SetString(PyExc_ValueError, "update_penalty: a float64 per cell");
        goto done;
    }
    const double *pen = b_pen.buf;
    if (!s->penalty) {
        s->penalty = calloc((size_t)s->n, sizeof(double));
        if (!s->penalty) {
            PyErr_NoMemory();
            goto done;
        }
    }
    int64_t lo = s->n, hi = -1;
    Py_ssize_t changed = 0;
    for (int64_t v = 0; v < s->n; v++) {
        if (pen[v] != s->penalty[v]) {
            touch_block(s, v, &lo, &hi);
            changed++;
        }
        s->penalty[v] = pen[v]; /* every value, as the reference keeps the new list */
    }
    if (!repair(s, lo, hi)) {
        PyErr_NoMemory();
        goto done;
    }
    result = PyLong_FromSsize_t(changed);
done:
    PyBuffer_Release(&b_pen);
    return result;
}

static PyObject *Search_rhs_at(Search *s, PyObject *args) {
    Py_ssize_t v;
    if (!PyArg_ParseTuple(args, "n", &v) || !ready(s))
        return NULL;
    if (v < 0 || v >= s->n) {
        PyErr_SetString(PyExc_ValueError, "cell outside the grid");
        return NULL;
    }
    return PyFloat_FromDouble(s->rhs[v]);
}

static PyObject *double_list(const double *values, Py_ssize_t n) {
    PyObject *list = PyList_New(n);
    if (!list)
        return NULL;
    for (Py_ssize_t i = 0; i < n; i++) {
        PyObject *x = PyFloat_FromDouble(values[i]);
        if (!x) {
            Py_DECREF(list);
            return NULL;
        }
        PyList_SET_ITEM(list, i, x);
    }
    return list;
}

static PyObject *Search_values(Search *s, PyObject *Py_UNUSED(ignored)) {
    if (!ready(s))
        return NULL;
    PyObject *g = double_list(s->g, s->n), *rhs = g ? double_list(s->rhs, s->n) : NULL;
    if (!rhs) {
        Py_XDECREF(g);
        return NULL;
    }
    return Py_BuildValue("NN", g, rhs);
}

static PyObject *Search_masks(Search *s, PyObject *Py_UNUSED(ignored)) {
    if (!ready(s))
        return NULL;
    return PyBytes_FromStringAndSize((const char *)s->masks, s->n);
}

static PyObject *Search_expansions(Search *s, void *Py_UNUSED(closure)) {
    return PyLong_FromSsize_t(s->expansions);
}

static PyMethodDef Search_methods[] = {
    {"compute", (PyCFunction)Search_compute, METH_VARARGS, "compute(start, km): expand until start is consistent."},
    {"path", (PyCFunction)Search_path, METH_VARARGS, "path(start): flat cells to the goal, or None."},
    {"update_cells", (PyCFunction)Search_update_cells, METH_VARARGS,
     "update_cells(cells int64, occupied uint8, start, km): set cells and repair their blocks."},
    {"update_penalty", (PyCFunction)Search_update_penalty, METH_VARARGS,
     "update_penalty(penalty float64, start, km) -> changed cells; repairs their blocks."},
    {"rhs_at", (PyCFunction)Search_rhs_at, METH_VARARGS, "rhs of one vertex."},
    {"values", (PyCFunction)Search_values, METH_NOARGS, "(g, rhs) as lists."},
    {"masks", (PyCFunction)Search_masks, METH_NOARGS, "the legal-move masks, a byte per cell."},
    {NULL, NULL, 0, NULL},
};

static PyGetSetDef Search_getset[] = {
    {"expansions", (getter)Search_expansions, NULL, "vertices expanded over every compute", NULL},
    {NULL, NULL, NULL, NULL, NULL},
};

static PyTypeObject SearchType = {
    PyVarObject_HEAD_INIT(NULL, 0)
    .tp_name = "swarmnav.planners._dstar_lite.Search",
    .tp_basicsize = sizeof(Search),
    .tp_flags = Py_TPFLAGS_DEFAULT,
    .tp_doc = "D* Lite's state and its loops (planners/dstar_lite.py DStarLite).",
    .tp_new = PyType_GenericNew,
    .tp_init = (initproc)Search_init,
    .tp_dealloc = (destructor)Search_dealloc,
    .tp_methods = Search_methods,
    .tp_getset = Search_getset,
};

static struct PyModuleDef module = {PyModuleDef_HEAD_INIT, "_dstar_lite",
                                   "D* Lite of planners/dstar_lite.py, compiled.", -1, NULL,
                                   NULL, NULL, NULL, NULL};

PyMODINIT_FUNC PyInit__dstar_lite(void) {
    if (PyType_Ready(&SearchType) < 0)
        return NULL;
    PyObject *m = PyModule_Create(&module);
    if (!m)
        return NULL;
    if (PyModule_AddObjectRef(m, "Search", (PyObject *)&SearchType) < 0) {
        Py_DECREF(m);
        return NULL;
    }
    return m;
}
