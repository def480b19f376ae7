/*
 * The C interface end to end, and every misuse it must survive: run under valgrind by
 * tests/capi.rs. Exits 0 when every check holds, prints the first failure otherwise.
 *
 *   smoke MESH.obj OUT.vdb
 */
#include <voxelkit.h>

#include "check.h"

#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

static int stop_at_once(uint64_t done, uint64_t total, void *user_data) {
    (void)done;
    (void)total;
    *(int *)user_data += 1;
    return 1;
}

static int stop_half_way(uint64_t done, uint64_t total, void *user_data) {
    *(uint64_t *)user_data = done;
    return 2 * done >= total;
}

static int count_calls(uint64_t done, uint64_t total, void *user_data) {
    (void)total;
    if (done > 0) *(int *)user_data += 1;
    return 0;
}

/* A closed unit cube as 12 triangles, outward. */
static vk_mesh *cube(void) {
    static const double p[] = {0, 0, 0, 1, 0, 0, 1, 1, 0, 0, 1, 0, 0, 0, 1, 1, 0, 1, 1, 1, 1, 0, 1, 1};
    static const uint32_t t[] = {0, 2, 1, 0, 3, 2, 4, 5, 6, 4, 6, 7, 0, 1, 5, 0, 5, 4,
                                 1, 2, 6, 1, 6, 5, 2, 3, 7, 2, 7, 6, 3, 0, 4, 3, 4, 7};
    vk_mesh *m = NULL;
    OK(vk_mesh_from_triangles(p, 8, t, 12, &m));
    return m;
}

int main(int argc, char **argv) {
    if (argc != 3) {
        fprintf(stderr, "usage: %s MESH.obj OUT.vdb\n", argv[0]);
        return 2;
    }
    CHECK(strlen(vk_version()) > 0);

    vk_options *opts = NULL;
    OK(vk_options_new(&opts));
    OK(vk_options_set_resolution(opts, 40));
    OK(vk_options_set_threads(opts, 2));

    /* A mesh from a file: separating surface with normals, then projective. */
    vk_mesh *mesh = NULL;
    OK(vk_mesh_load(argv[1], &mesh));
    size_t vertices = 0, faces = 0;
    OK(vk_mesh_counts(mesh, &vertices, &faces));
    CHECK(vertices > 0 && faces > 0);
    int calls = 0;
    OK(vk_options_set_progress(opts, count_calls, &calls));
    OK(vk_options_set_normals(opts, 1));
    vk_grid *surface = NULL;
    OK(vk_voxelize_mesh(mesh, opts, &surface));
    CHECK(calls > 0);
    OK(vk_options_set_progress(opts, NULL, NULL));
    uint64_t voxels = 0;
    size_t leaves = 0;
    OK(vk_grid_voxel_count(surface, &voxels));
    OK(vk_grid_leaf_count(surface, &leaves));
    CHECK(voxels > 0 && leaves > 0);

    /* Leaves, normals and voxels into caller buffers; the counts agree. */
    int32_t *origins = malloc(3 * leaves * sizeof *origins);
    uint64_t *masks = malloc(8 * leaves * sizeof *masks);
    float *normals = malloc(3 * 512 * leaves * sizeof *normals);
    OK(vk_grid_copy_leaves(surface, 0, leaves, origins, masks));
    OK(vk_grid_copy_normals(surface, 0, leaves, normals));
    uint64_t bits = 0;
    for (size_t i = 0; i < 8 * leaves; i++) bits += (uint64_t)__builtin_popcountll(masks[i]);
    CHECK(bits == voxels);
    CHECK(vk_grid_copy_colors(surface, 0, leaves, normals) == VK_ERROR_INVALID_ARGUMENT);
    CHECK(vk_grid_copy_leaves(surface, leaves, 1, origins, masks) == VK_ERROR_INVALID_ARGUMENT);
    size_t written = 0;
    CHECK(vk_grid_copy_voxels(surface, NULL, 0, &written) == VK_ERROR_BUFFER_TOO_SMALL);
    CHECK(written == voxels);
    int64_t *coords = malloc(3 * written * sizeof *coords);
    OK(vk_grid_copy_voxels(surface, coords, written, &written));
    free(coords);
    free(normals);
    free(masks);
    free(origins);
    double voxel_size = 0, origin[3];
    OK(vk_grid_transform(surface, &voxel_size, origin));
    CHECK(voxel_size > 0);

    /* Write and read back. */
    OK(vk_grid_write_vdb(surface, argv[2]));
    vk_grid *back = NULL;
    OK(vk_grid_read_vdb(argv[2], "density", &back));
    uint64_t back_voxels = 0;
    OK(vk_grid_voxel_count(back, &back_voxels));
    CHECK(back_voxels == voxels);
    CHECK(vk_grid_read_vdb(argv[2], "no-such-grid", &back) == VK_ERROR_VDB);

    /* The surface's measures, and a solid by each fill method. */
    vk_measures flooded, m;
    OK(vk_measure_surface(surface, &flooded));
    CHECK(flooded.inside_voxels > 0 && flooded.volume_inside < flooded.volume_with_surface);
    vk_mesh *box = cube();
    OK(vk_options_set_flood(opts, 1, 64));
    OK(vk_options_set_depth_layers(opts, 3, 1));
    CHECK(vk_options_set_depth_layers(opts, 17, 1) == VK_ERROR_INVALID_ARGUMENT);
    for (int method = VK_FILL_FLOOD; method <= VK_FILL_BEAM; method++) {
        vk_grid *solid = NULL;
        OK(vk_options_set_fill_method(opts, (vk_fill_method)method));
        OK(vk_fill_mesh(box, opts, &solid, &m));
        CHECK(m.volume_inside <= 1.0 + 1e-9 && m.volume_with_surface >= 1.0 - 1e-9);
        /* Leaves plus whole-block tiles hold every voxel of the solid. */
        size_t n_leaves = 0, n_tiles = 0;
        uint64_t n_voxels = 0, counted = 0;
        OK(vk_grid_leaf_count(solid, &n_leaves));
        OK(vk_grid_tile_count(solid, &n_tiles));
        OK(vk_grid_voxel_count(solid, &n_voxels));
        CHECK(n_tiles > 0);
        int32_t *leaf_origins = malloc(3 * sizeof(int32_t) * (n_leaves + 1));
        uint64_t *leaf_masks = malloc(8 * sizeof(uint64_t) * (n_leaves + 1));
        int32_t *tile_origins = malloc(3 * sizeof(int32_t) * n_tiles);
        int32_t *tile_edges = malloc(sizeof(int32_t) * n_tiles);
        OK(vk_grid_copy_leaves(solid, 0, n_leaves, leaf_origins, leaf_masks));
        OK(vk_grid_copy_tiles(solid, 0, n_tiles, tile_origins, tile_edges));
        CHECK(vk_grid_copy_tiles(solid, n_tiles, 1, tile_origins, tile_edges) == VK_ERROR_INVALID_ARGUMENT);
        for (size_t k = 0; k < 8 * n_leaves; k++) counted += (uint64_t)__builtin_popcountll(leaf_masks[k]);
        for (size_t k = 0; k < n_tiles; k++) {
            CHECK(tile_edges[k] == 8 || tile_edges[k] == 128);
            counted += (uint64_t)tile_edges[k] * tile_edges[k] * tile_edges[k];
        }
        CHECK(counted == n_voxels);
        free(leaf_origins);
        free(leaf_masks);
        free(tile_origins);
        free(tile_edges);
        OK(vk_grid_free(solid));
    }

    /* Booleans: a - a is empty, a | a is a. */
    vk_grid *diff = NULL, *both = NULL;
    OK(vk_grid_combine(surface, back, VK_DIFFERENCE, 0, &diff));
    OK(vk_grid_combine(surface, back, VK_UNION, 0, &both));
    uint64_t n_diff = 1, n_both = 0;
    OK(vk_grid_voxel_count(diff, &n_diff));
    OK(vk_grid_voxel_count(both, &n_both));
    CHECK(n_diff == 0 && n_both == voxels);
    OK(vk_grid_free(diff));
    OK(vk_grid_free(both));

    /* The other voxelizers. */
    vk_grid *g = NULL;
    OK(vk_options_set_surface_method(opts, VK_SURFACE_PROJECTIVE));
    /* Normals are the separating surface's: the projective method refuses them. */
    CHECK(vk_voxelize_mesh(mesh, opts, &g) == VK_ERROR_INVALID_ARGUMENT && g == NULL);
    OK(vk_options_set_normals(opts, 0));
    OK(vk_voxelize_mesh(mesh, opts, &g));
    OK(vk_grid_free(g));
    OK(vk_voxelize_lines(mesh, opts, &g));
    OK(vk_grid_free(g));
    OK(vk_options_set_subdivision(opts, 4, 1));
    CHECK(vk_options_set_subdivision(opts, 0, 0) == VK_ERROR_INVALID_ARGUMENT);
    OK(vk_voxelize_subdivision(box, opts, &g));
    OK(vk_grid_free(g));
    /* The unit cube as a Catmull-Clark solid: a rounded blob inside it. */
    vk_measures cc;
    OK(vk_fill_subdivision(box, opts, &g, &cc));
    CHECK(cc.inside_voxels > 0 && cc.volume_inside < 1.0 && cc.volume_with_surface > 0.1);
    OK(vk_grid_free(g));
    const double lo[3] = {-1, -1, -1}, hi[3] = {1, 1, 1};
    OK(vk_voxelize_formula("x^2 + y^2 + z^2 - 0.5", VK_CARTESIAN, lo, hi, opts, &g));
    OK(vk_grid_free(g));
    CHECK(vk_voxelize_formula("x^2 +* y", VK_CARTESIAN, lo, hi, opts, &g) == VK_ERROR_PARSE);
    CHECK(strstr(vk_last_error(), "column") != NULL);
    const double nan_lo[3] = {-1, 0.0 / 0.0, -1};
    CHECK(vk_voxelize_formula("x", VK_CARTESIAN, nan_lo, hi, opts, &g) == VK_ERROR_INVALID_ARGUMENT);

    /* Cancellation: by the flag, and by the progress callback. */
    int32_t cancel = 1;
    OK(vk_options_set_cancel_flag(opts, &cancel));
    CHECK(vk_voxelize_mesh(mesh, opts, &g) == VK_ERROR_CANCELLED);
    OK(vk_options_set_cancel_flag(opts, NULL));
    int stops = 0;
    OK(vk_options_set_progress(opts, stop_at_once, &stops));
    CHECK(vk_voxelize_mesh(mesh, opts, &g) == VK_ERROR_CANCELLED);
    CHECK(stops >= 1);

    /* Cancelled half-way by the callback: every long call stops, returns nothing, leaks
     * nothing (valgrind checks that). */
    uint64_t reached = 0;
    OK(vk_options_set_progress(opts, stop_half_way, &reached));
    g = NULL;
    CHECK(vk_voxelize_mesh(mesh, opts, &g) == VK_ERROR_CANCELLED && g == NULL);
    CHECK(vk_voxelize_lines(mesh, opts, &g) == VK_ERROR_CANCELLED && g == NULL);
    CHECK(vk_voxelize_subdivision(box, opts, &g) == VK_ERROR_CANCELLED && g == NULL);
    CHECK(vk_voxelize_formula("x^2 + y^2 + z^2 - 0.5", VK_CARTESIAN, lo, hi, opts, &g) ==
          VK_ERROR_CANCELLED && g == NULL);
    for (int method = VK_FILL_FLOOD; method <= VK_FILL_BEAM; method++) {
        OK(vk_options_set_fill_method(opts, (vk_fill_method)method));
        CHECK(vk_fill_mesh(mesh, opts, &g, NULL) == VK_ERROR_CANCELLED && g == NULL);
    }
    OK(vk_options_set_fill_method(opts, VK_FILL_FLOOD));
    CHECK(reached > 0);
    OK(vk_options_set_progress(opts, NULL, NULL));

    /* An impossible grid: every call refuses it at once, with the estimate. */
    OK(vk_options_set_voxel_size(opts, 1e-9));
    CHECK(vk_voxelize_mesh(mesh, opts, &g) == VK_ERROR_TOO_LARGE);
    CHECK(strstr(vk_last_error(), "MiB") != NULL);
    CHECK(vk_voxelize_lines(mesh, opts, &g) == VK_ERROR_TOO_LARGE);
    CHECK(vk_voxelize_subdivision(box, opts, &g) == VK_ERROR_TOO_LARGE);
    CHECK(vk_fill_mesh(mesh, opts, &g, NULL) == VK_ERROR_TOO_LARGE);
    OK(vk_options_set_resolution(opts, 65536));
    CHECK(vk_voxelize_formula("x^2 + y^2 + z^2 - 0.5", VK_CARTESIAN, lo, hi, opts, &g) ==
          VK_ERROR_TOO_LARGE);
    OK(vk_options_set_resolution(opts, 40));
    OK(vk_options_set_max_memory(opts, 1));
    CHECK(vk_voxelize_mesh(mesh, opts, &g) == VK_ERROR_TOO_LARGE);
    /* 0 MiB and 0 threads mean the defaults, as in every front end: the memory available and
     * every core. */
    OK(vk_options_set_max_memory(opts, 0));
    OK(vk_options_set_threads(opts, 0));
    vk_grid *defaults = NULL;
    OK(vk_voxelize_mesh(mesh, opts, &defaults));
    OK(vk_grid_free(defaults));
    OK(vk_options_set_threads(opts, 2));
    /* The write options: every compression, half floats, and a bad code. */
    for (int c = VK_COMPRESSION_BLOSC; c <= VK_COMPRESSION_NONE; c++) {
        OK(vk_options_set_compression(opts, (vk_compression)c));
        OK(vk_grid_write_vdb_with(surface, argv[2], opts));
    }
    OK(vk_options_set_half(opts, 1));
    OK(vk_grid_write_vdb_with(surface, argv[2], opts));
    CHECK(vk_options_set_compression(opts, (vk_compression)7) == VK_ERROR_INVALID_ARGUMENT);
    CHECK(strstr(vk_last_error(), "compression") != NULL);
    CHECK(vk_options_set(opts, "mesh", "band", "\"wide\"") == VK_ERROR_INVALID_ARGUMENT);
    CHECK(strstr(vk_last_error(), "band") != NULL);
    CHECK(vk_options_set(opts, "nothing", "band", "1") == VK_ERROR_INVALID_ARGUMENT);
    CHECK(vk_options_set(opts, "mesh", "band", "not json") == VK_ERROR_INVALID_ARGUMENT);
    CHECK(vk_options_set(opts, "mesh", NULL, "1") == VK_ERROR_INVALID_ARGUMENT);

    /* Misuse: NULL, wrong kinds, bad values, bad files, double frees, panics. */
    CHECK(vk_voxelize_mesh(NULL, opts, &g) == VK_ERROR_INVALID_HANDLE);
    CHECK(vk_voxelize_mesh(mesh, NULL, &g) == VK_ERROR_INVALID_HANDLE);
    CHECK(vk_voxelize_mesh(mesh, opts, NULL) == VK_ERROR_INVALID_ARGUMENT);
    CHECK(vk_voxelize_mesh((const vk_mesh *)surface, opts, &g) == VK_ERROR_INVALID_HANDLE);
    CHECK(strstr(vk_last_error(), "vk_grid") != NULL);
    CHECK(vk_grid_voxel_count(surface, NULL) == VK_ERROR_INVALID_ARGUMENT);
    CHECK(vk_options_set_separability(opts, 18) == VK_ERROR_INVALID_ARGUMENT);
    CHECK(vk_options_set_resolution(opts, 0) == VK_ERROR_INVALID_ARGUMENT);
    CHECK(vk_options_set_voxel_size(opts, -1.0) == VK_ERROR_INVALID_ARGUMENT);
    CHECK(vk_options_set_fill_method(opts, (vk_fill_method)7) == VK_ERROR_INVALID_ARGUMENT);
    CHECK(vk_mesh_load("no/such/file.obj", &mesh) == VK_ERROR_IO);
    CHECK(strstr(vk_last_error(), "no/such/file.obj") != NULL);
    CHECK(vk_mesh_load(NULL, &mesh) == VK_ERROR_INVALID_ARGUMENT);
    static const double bad_p[] = {0, 0, 0, 1, 0, 0, 0, 1, 0};
    static const uint32_t bad_t[] = {0, 1, 7};
    vk_mesh *bad = NULL;
    CHECK(vk_mesh_from_triangles(bad_p, 3, bad_t, 1, &bad) == VK_ERROR_BAD_MESH);
    /* Arrays count vertices from 0, and so do the messages about them. */
    CHECK(strstr(vk_last_error(), "vertex index 7 ") != NULL);
    CHECK(vk_mesh_from_triangles(NULL, 3, bad_t, 1, &bad) == VK_ERROR_INVALID_ARGUMENT);
    /* Counts whose copy cannot be held are refused before anything is read or allocated. */
    CHECK(vk_mesh_from_triangles(bad_p, 3, bad_t, SIZE_MAX / 24 + 1, &bad) == VK_ERROR_INVALID_ARGUMENT);
    CHECK(vk_mesh_from_triangles(bad_p, SIZE_MAX / 3, bad_t, 1, &bad) == VK_ERROR_INVALID_ARGUMENT);
    CHECK(vk_mesh_from_triangles(bad_p, 3, bad_t, (size_t)1 << 40, &bad) == VK_ERROR_TOO_LARGE);
    CHECK(bad == NULL);
    CHECK(vk_grid_write_vdb(surface, "/no/such/dir/out.vdb") != VK_OK);
    CHECK(vk_debug_panic() == VK_ERROR_INTERNAL);
    CHECK(strstr(vk_last_error(), "vk_debug_panic") != NULL);

    OK(vk_grid_free(back));
    CHECK(vk_grid_free(back) == VK_ERROR_INVALID_HANDLE);
    OK(vk_grid_free(surface));
    OK(vk_mesh_free(box));
    OK(vk_mesh_free(mesh));
    CHECK(vk_mesh_free(mesh) == VK_ERROR_INVALID_HANDLE);
    OK(vk_options_free(opts));
    OK(vk_grid_free(NULL));
    CHECK(strcmp(vk_last_error(), "") == 0);

    if (failures == 0) printf("ok\n");
    return failures == 0 ? 0 : 1;
}
