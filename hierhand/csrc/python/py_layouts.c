/* hierhand._native.LAYOUTS, RECORD_LAYOUTS, BLOCK_CLASSES, INPUT_PORTS and DIMENSIONS: layouts.h's
 * tables for Python.
 *
 * LAYOUTS[name] is (size, ((slot, offset, width), ...), prefix, size name) for every layout
 * of HH_LAYOUTS and HH_RECORDS, the offsets being the C enum's very constants (HH_REFLEX_P_KI
 * for LAYOUTS["REFLEX_PARAMS"]'s slot KI, prefix "HH_REFLEX_P_"): the preprocessor writes
 * this table and the enums from the one declaration of each array. RECORD_LAYOUTS names the record layout of each
 * kernel type ({"GraspReflex": "REFLEX_RECORD", ...}), BLOCK_CLASSES the block class of each
 * record ("hierhand.control.grasp_reflex:GraspReflex", ...) in HH_RECORDS' order. INPUT_PORTS[name] is a list of input
 * ports in the same form, each port's index in place of an offset. hierhand.layouts makes
 * them Layout objects and port mappings.
 */
#include "py_common.h"

#include "../kernel_types.h"

typedef struct {
    const char *name;
    long offset, width;
} slot_entry;

typedef struct {
    const char *name;
    const slot_entry *slots;
    size_t count;
    long size;
    const char *prefix, *size_name; /* of its C names */
} layout_entry;

#define SLOT_ENTRY(P, NAME, WIDTH) {#NAME, P##NAME, (WIDTH)},
#define SLOT_TABLE(NAME, P, SLOTS, SIZE) static const slot_entry NAME##_SLOTS_[] = {SLOTS(SLOT_ENTRY, P)};
#define RECORD_SLOT_TABLE(NAME, P, SLOTS, SIZE, TYPES, BLOCK) SLOT_TABLE(NAME, P, SLOTS, SIZE)
HH_LAYOUTS(SLOT_TABLE)
HH_RECORDS(RECORD_SLOT_TABLE)

#define LAYOUT_ENTRY(NAME, P, SLOTS, SIZE)                                                                         \
    {#NAME, NAME##_SLOTS_, sizeof NAME##_SLOTS_ / sizeof NAME##_SLOTS_[0], SIZE, #P, #SIZE},
#define RECORD_LAYOUT_ENTRY(NAME, P, SLOTS, SIZE, TYPES, BLOCK) LAYOUT_ENTRY(NAME, P, SLOTS, SIZE)
static const layout_entry LAYOUTS[] = {HH_LAYOUTS(LAYOUT_ENTRY) HH_RECORDS(RECORD_LAYOUT_ENTRY)};

#define PORT_TABLE(NAME, P, PORTS, COUNT) static const slot_entry NAME##_SLOTS_[] = {PORTS(SLOT_ENTRY, P)};
HH_INPUT_PORTS(PORT_TABLE)
static const layout_entry INPUT_PORTS[] = {HH_INPUT_PORTS(LAYOUT_ENTRY)};

/* (size, ((slot, offset, width), ...), prefix, size name) of one layout. */
static PyObject *layout_tuple(const layout_entry *layout)
{
    PyObject *slots = PyTuple_New((Py_ssize_t)layout->count);
    for (size_t i = 0; slots != NULL && i < layout->count; i++) {
        const slot_entry *s = &layout->slots[i];
        PyObject *slot = Py_BuildValue("(sll)", s->name, s->offset, s->width);
        if (slot == NULL)
            Py_CLEAR(slots);
        else
            PyTuple_SetItem(slots, (Py_ssize_t)i, slot); /* steals slot */
    }
    if (slots == NULL)
        return NULL;
    return Py_BuildValue("(lNss)", layout->size, slots, layout->prefix, layout->size_name);
}

/* module.name = value, taking the reference to value (NULL: an error already set). */
static int add_owned(PyObject *module, const char *name, PyObject *value)
{
    int failed = value == NULL || PyModule_AddObjectRef(module, name, value) != 0;
    Py_XDECREF(value);
    return failed ? -1 : 0;
}

/* module.name = {layout name: layout_tuple} of the n entries. */
static int add_layouts(PyObject *module, const char *name, const layout_entry *entries, size_t n)
{
    PyObject *layouts = PyDict_New();
    for (size_t i = 0; layouts != NULL && i < n; i++) {
        PyObject *layout = layout_tuple(&entries[i]);
        if (layout == NULL || PyDict_SetItemString(layouts, entries[i].name, layout) != 0)
            Py_CLEAR(layouts);
        Py_XDECREF(layout);
    }
    return add_owned(module, name, layouts);
}

#define RECORD_OF_TYPES(NAME, P, SLOTS, SIZE, TYPES, BLOCK) {#NAME, TYPES},
static const struct {
    const char *layout;
    const blk_kernel_type *types;
} RECORD_LAYOUTS[] = {HH_RECORDS(RECORD_OF_TYPES)};

static int add_record_layouts(PyObject *module)
{
    PyObject *records = PyDict_New();
    for (size_t i = 0; records != NULL && i < sizeof RECORD_LAYOUTS / sizeof RECORD_LAYOUTS[0]; i++)
        for (const blk_kernel_type *k = RECORD_LAYOUTS[i].types; records != NULL && k->name != NULL; k++) {
            PyObject *layout = PyUnicode_FromString(RECORD_LAYOUTS[i].layout);
            if (layout == NULL || PyDict_SetItemString(records, k->name, layout) != 0)
                Py_CLEAR(records);
            Py_XDECREF(layout);
        }
    return add_owned(module, "RECORD_LAYOUTS", records);
}

#define BLOCK_CLASS(NAME, P, SLOTS, SIZE, TYPES, BLOCK) BLOCK,
static const char *const BLOCK_CLASSES[] = {HH_RECORDS(BLOCK_CLASS)};

static int add_block_classes(PyObject *module)
{
    const size_t n = sizeof BLOCK_CLASSES / sizeof BLOCK_CLASSES[0];
    PyObject *classes = PyTuple_New((Py_ssize_t)n);
    for (size_t i = 0; classes != NULL && i < n; i++) {
        PyObject *path = PyUnicode_FromString(BLOCK_CLASSES[i]);
        if (path == NULL)
            Py_CLEAR(classes);
        else
            PyTuple_SetItem(classes, (Py_ssize_t)i, path); /* steals path */
    }
    return add_owned(module, "BLOCK_CLASSES", classes);
}

#define DIMENSION_ENTRY(NAME, VALUE) {#NAME, HH_##NAME},
static const struct {
    const char *name;
    long value;
} DIMENSIONS[] = {HH_DIMENSIONS(DIMENSION_ENTRY)};

static int add_dimensions(PyObject *module)
{
    PyObject *dimensions = PyDict_New();
    for (size_t i = 0; dimensions != NULL && i < sizeof DIMENSIONS / sizeof DIMENSIONS[0]; i++) {
        PyObject *value = PyLong_FromLong(DIMENSIONS[i].value);
        if (value == NULL || PyDict_SetItemString(dimensions, DIMENSIONS[i].name, value) != 0)
            Py_CLEAR(dimensions);
        Py_XDECREF(value);
    }
    return add_owned(module, "DIMENSIONS", dimensions);
}

int hh_py_add_layouts(PyObject *module)
{
    return add_layouts(module, "LAYOUTS", LAYOUTS, sizeof LAYOUTS / sizeof LAYOUTS[0]) != 0 ||
                   add_layouts(module, "INPUT_PORTS", INPUT_PORTS, sizeof INPUT_PORTS / sizeof INPUT_PORTS[0]) != 0 ||
                   add_record_layouts(module) != 0 || add_block_classes(module) != 0 || add_dimensions(module) != 0
               ? -1
               : 0;
}
