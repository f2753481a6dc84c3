/* The resources of an exported FMU (BLK_EXPORT_RESOURCE, written by blocks/fmu_export; its
 * format is in export_instance.h) read into the instance's blk_export, every count, index
 * and offset checked against the file's size and the op table, and each block's kind
 * looked up among the kernel types this binary holds; and the folder of the resources
 * from the URI an importer gives. */
#include <ctype.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "export_internal.h"

int blk_path_from_uri(const char *uri, char *out, size_t size)
{
    const char *p = uri;
    if (strncmp(p, "file:", 5) == 0) {
        p += 5;
        if (strncmp(p, "///", 3) == 0)
            p += 2; /* file:///path */
        else if (strncmp(p, "//localhost/", 12) == 0)
            p += 11; /* file://localhost/path */
        else if (strncmp(p, "//", 2) == 0)
            return -1; /* a remote host */
    }
    size_t n = 0;
    while (*p != '\0') {
        char c = *p++;
        if (c == '%' && isxdigit((unsigned char)p[0]) && isxdigit((unsigned char)p[1])) {
            char hex[3] = {p[0], p[1], '\0'};
            c = (char)strtol(hex, NULL, 16);
            p += 2;
        }
        if (n + 1 >= size)
            return -1;
        out[n++] = c;
    }
    out[n] = '\0';
    return n > 0 ? 0 : -1;
}

typedef struct {
    const int64_t *w;
    int64_t n, at;
    int ok;
} reader;

static int64_t word(reader *r)
{
    if (!r->ok || r->at >= r->n) {
        r->ok = 0;
        return 0;
    }
    return r->w[r->at++];
}

/* The next count words (count >= 0, within the file); NULL otherwise. */
static const int64_t *words(reader *r, int64_t count)
{
    if (!r->ok || count < 0 || count > r->n - r->at) {
        r->ok = 0;
        return NULL;
    }
    const int64_t *p = r->w + r->at;
    r->at += count;
    return p;
}

/* A count, then that many words; a count of at most limit. */
static const int64_t *counted(reader *r, int64_t *count, int64_t limit)
{
    *count = word(r);
    if (*count < 0 || *count > limit)
        r->ok = 0;
    return words(r, *count);
}

static char *string(reader *r)
{
    int64_t length = word(r);
    if (length < 0 || length > 1 << 20) {
        r->ok = 0;
        return NULL;
    }
    const int64_t *p = words(r, (length + 7) / 8);
    char *s = p != NULL ? malloc((size_t)length + 1) : NULL;
    if (s == NULL) {
        r->ok = 0;
        return NULL;
    }
    memcpy(s, p, (size_t)length);
    s[length] = '\0';
    return s;
}

static int64_t index_in(reader *r, int64_t limit)
{
    int64_t i = word(r);
    if (i < 0 || i >= limit)
        r->ok = 0;
    return i;
}

void ex_free_export(blk_export *x)
{
    for (int64_t b = 0; x->blocks != NULL && b < x->n_blocks; b++) {
        free(x->blocks[b].name);
        free(x->blocks[b].kind);
    }
    for (int64_t p = 0; x->params != NULL && p < x->n_params; p++)
        free(x->params[p].name);
    free(x->blocks);
    free(x->inputs);
    free(x->params);
    free(x->follows);
    free(x->token);
    free(x->model);
    free(x->data);
    memset(x, 0, sizeof *x);
}

static const blk_kernel_type *kernel_type(const char *kind)
{
    for (const blk_kernel_type *const *set = blk_export_kernel_sets; *set != NULL; set++)
        for (const blk_kernel_type *k = *set; k->name != NULL; k++)
            if (strcmp(k->name, kind) == 0)
                return k;
    return NULL;
}

static void *read_file(blk_instance *inst, const char *path, int64_t *words_read)
{
    FILE *file = fopen(path, "rb");
    if (file == NULL) {
        LOG_ERROR(inst, "cannot open %s: the FMU's resources are missing or unreadable", path);
        return NULL;
    }
    int64_t *data = NULL;
    long size = fseek(file, 0, SEEK_END) == 0 ? ftell(file) : -1;
    if (size > 0 && size % 8 == 0 && fseek(file, 0, SEEK_SET) == 0 && (data = malloc((size_t)size)) != NULL &&
        fread(data, 1, (size_t)size, file) != (size_t)size) {
        free(data);
        data = NULL;
    }
    fclose(file);
    if (data == NULL)
        LOG_ERROR(inst, "cannot read %s (%ld bytes)", path, size);
    *words_read = size / 8;
    return data;
}

/* zlib's CRC-32 of n bytes. */
static uint32_t crc32_of(const unsigned char *p, size_t n)
{
    uint32_t crc = 0xFFFFFFFFu;
    for (size_t i = 0; i < n; i++) {
        crc ^= p[i];
        for (int k = 0; k < 8; k++)
            crc = (crc >> 1) ^ (0xEDB88320u & (0u - (crc & 1u)));
    }
    return ~crc;
}

/* The blocks: names, kinds (looked up in this binary), records and states. */
static void read_blocks(reader *r, blk_export *x)
{
    x->n_blocks = word(r);
    if (!r->ok || x->n_blocks != x->table.n_blocks || (x->blocks = calloc((size_t)x->n_blocks + 1, sizeof *x->blocks)) == NULL) {
        r->ok = 0;
        return;
    }
    for (int64_t b = 0; r->ok && b < x->n_blocks; b++) {
        ex_block *k = x->blocks + b;
        k->name = string(r);
        k->kind = string(r);
        k->record = (const double *)counted(r, &k->n_record, r->n);
        k->built_state = (int)word(r);
        k->state = (const double *)counted(r, &k->n_state, r->n);
    }
}

static void read_variables(reader *r, blk_export *x)
{
    int64_t arena = x->table.header[BLK_H_ARENA];
    x->n_inputs = word(r);
    if (r->ok && (x->n_inputs < 0 || x->n_inputs > r->n || (x->inputs = calloc((size_t)x->n_inputs + 1, sizeof *x->inputs)) == NULL))
        r->ok = 0;
    for (int64_t i = 0; r->ok && i < x->n_inputs; i++) {
        int64_t bits = word(r);
        memcpy(&x->inputs[i].start, &bits, sizeof bits);
        x->inputs[i].offsets = counted(r, &x->inputs[i].n, arena);
        for (int64_t j = 0; r->ok && j < x->inputs[i].n; j++)
            if (x->inputs[i].offsets[j] < 0 || x->inputs[i].offsets[j] >= arena)
                r->ok = 0;
    }
    x->outputs = counted(r, &x->n_outputs, r->n);
    for (int64_t i = 0; r->ok && i < x->n_outputs; i++)
        if (x->outputs[i] < 0 || x->outputs[i] >= arena)
            r->ok = 0;
    x->n_params = word(r);
    if (r->ok && (x->n_params < 0 || x->n_params > r->n || (x->params = calloc((size_t)x->n_params + 1, sizeof *x->params)) == NULL))
        r->ok = 0;
    for (int64_t p = 0; r->ok && p < x->n_params; p++) {
        ex_param *q = x->params + p;
        q->block = index_in(r, x->n_blocks);
        q->slot = word(r);
        q->finite = word(r);
        q->name = string(r);
        if (r->ok && (q->slot < 0 || q->slot >= x->blocks[q->block].n_record))
            r->ok = 0;
    }
    x->n_follows = word(r);
    if (r->ok && (x->n_follows < 0 || x->n_follows > r->n || (x->follows = calloc((size_t)x->n_follows + 1, sizeof *x->follows)) == NULL))
        r->ok = 0;
    for (int64_t f = 0; r->ok && f < x->n_follows; f++) {
        ex_follow *g = x->follows + f;
        g->block = index_in(r, x->n_blocks);
        g->slot = word(r);
        g->when = counted(r, &g->n_when, x->n_params);
        g->unless = counted(r, &g->n_unless, x->n_params);
        if (r->ok && (g->slot < 0 || g->slot >= x->blocks[g->block].n_record))
            r->ok = 0;
        for (int64_t j = 0; r->ok && j < g->n_when + g->n_unless; j++) {
            int64_t p = j < g->n_when ? g->when[j] : g->unless[j - g->n_when];
            if (p < 0 || p >= x->n_params)
                r->ok = 0;
        }
    }
    x->n_links = word(r);
    x->links = (const ex_link *)words(r, x->n_links * 5);
    for (int64_t l = 0; r->ok && l < x->n_links; l++) {
        const ex_link *k = x->links + l;
        if (k->block < 0 || k->block >= x->n_blocks || k->source < 0 || k->source >= x->n_blocks || k->length < 0 ||
            k->slot < 0 || k->length > x->blocks[k->block].n_record - k->slot || k->source_slot < 0 ||
            k->length > x->blocks[k->source].n_record - k->source_slot)
            r->ok = 0;
    }
}

/* Read BLK_EXPORT_RESOURCE: 0, or -1 after logging why. */
/* The path of resource file ``name`` in ``folder`` into path; 0, or -1 after logging why. */
static int resource_path(blk_instance *inst, const char *folder, const char *name, char *path, size_t size)
{
    size_t len = strlen(folder);
    const char *sep = len > 0 && folder[len - 1] == '/' ? "" : "/";
    if ((size_t)snprintf(path, size, "%s%s%s", folder, sep, name) >= size) {
        LOG_ERROR(inst, "the resource folder path is too long: %s", folder);
        return -1;
    }
    return 0;
}

int64_t *ex_read_resource_words(blk_instance *inst, const char *folder, const char *name, int64_t *n)
{
    char path[4096];
    return resource_path(inst, folder, name, path, sizeof path) != 0 ? NULL : read_file(inst, path, n);
}

int ex_read_resources(blk_instance *inst, const char *token, const char *folder)
{
    char path[4096];
    if (resource_path(inst, folder, BLK_EXPORT_RESOURCE, path, sizeof path) != 0)
        return -1;
    blk_export *x = &inst->x;
    int64_t n;
    x->data = read_file(inst, path, &n);
    if (x->data == NULL)
        return -1;
    if (n < 3 || (int64_t)crc32_of((const unsigned char *)x->data, (size_t)(n - 1) * 8) != x->data[n - 1]) {
        LOG_ERROR(inst, "%s is damaged: its checksum does not match its content", path);
        return -1;
    }
    reader r = {x->data, n - 1, 0, 1}; /* the words before the checksum */
    if (word(&r) != BLK_EXPORT_MAGIC || word(&r) != BLK_EXPORT_VERSION) {
        LOG_ERROR(inst, "%s is not the resource of a diagram FMU of this version", path);
        return -1;
    }
    x->token = string(&r);
    x->model = string(&r);
    if (r.ok && token != NULL && strcmp(token, x->token) != 0) {
        LOG_ERROR(inst, "instantiation token '%s' does not match this FMU's '%s' (%s)", token, x->token, path);
        return -1;
    }
    x->grid = word(&r);
    x->vr_input = word(&r);
    x->vr_output = word(&r);
    x->vr_param = word(&r);
    x->initial_outputs = word(&r);
    x->between = word(&r);
    x->lazy = word(&r);
    int64_t table_words;
    const int64_t *table = counted(&r, &table_words, r.n);
    const char *bad = NULL;
    if (r.ok)
        bad = blk_table_unpack(table, (size_t)table_words * 8, &x->table, &x->arena0);
    if (bad != NULL) {
        LOG_ERROR(inst, "%s: its op table is wrong: %s", path, bad);
        return -1;
    }
    int64_t programs = x->table.n_programs;
    if (r.ok && (x->grid <= 0 || x->initial_outputs < 0 || x->initial_outputs >= programs || x->between < -1 ||
                 x->between >= programs || x->lazy < -1 || x->lazy >= programs))
        r.ok = 0;
    for (int64_t e = 0; r.ok && e < x->table.n_events; e++)
        if (x->table.programs[x->table.events[e * BLK_E_N + BLK_E_PROGRAM] * BLK_PR_N + BLK_PR_FINAL] < 0)
            r.ok = 0;
    read_blocks(&r, x);
    read_variables(&r, x);
    if (!r.ok || word(&r) != BLK_EXPORT_MAGIC || r.at != r.n) {
        LOG_ERROR(inst, "%s is damaged or incomplete (at word %lld of %lld)", path, (long long)r.at,
                  (long long)r.n);
        return -1;
    }
    for (int64_t b = 0; b < x->n_blocks; b++) {
        ex_block *k = x->blocks + b;
        k->type = kernel_type(k->kind);
        if (k->type == NULL) {
            LOG_ERROR(inst, "block '%s': this FMU's binary has no kernel type '%s' (rebuild it with the sources of "
                            "the kind)", k->name, k->kind);
            return -1;
        }
    }
    return 0;
}
