/*
 * Every output in memory: a level set's values against the exact signed distance of a box,
 * its file, its measures and its use as a Boolean operand; a grid rebuilt from copied
 * leaves and tiles. Run (under valgrind) by tests/capi.rs; prints "ok" when every check
 * holds.
 *
 *   in_memory LEVEL_SET.vdb [LEVEL_SET.nvdb]
 */
#include <voxelkit.h>

#include "check.h"

#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

/* A closed box [0, 1] x [0, 1] x [0, 2] as 12 triangles, outward. */
static vk_mesh *box(void) {
    static const double p[] = {0, 0, 0, 1, 0, 0, 1, 1, 0, 0, 1, 0, 0, 0, 2, 1, 0, 2, 1, 1, 2, 0, 1, 2};
    static const uint32_t t[] = {0, 2, 1, 0, 3, 2, 4, 5, 6, 4, 6, 7, 0, 1, 5, 0, 5, 4,
                                 1, 2, 6, 1, 6, 5, 2, 3, 7, 2, 7, 6, 3, 0, 4, 3, 4, 7};
    vk_mesh *m = NULL;
    OK(vk_mesh_from_triangles(p, 8, t, 12, &m));
    return m;
}

/* The exact signed distance from p to the box, negative inside. */
static double box_distance(const double p[3]) {
    const double hi[3] = {1, 1, 2};
    double outside = 0, inside = -INFINITY;
    for (int a = 0; a < 3; a++) {
        double d = fmax(-p[a], p[a] - hi[a]);
        outside += d > 0 ? d * d : 0;
        inside = fmax(inside, d);
    }
    return outside > 0 ? sqrt(outside) : inside;
}

static void check_level_set(const vk_grid *sdf) {
    vk_grid_class kind = VK_GRID_VOXELS;
    float background = 0;
    double h = 0, origin[3];
    OK(vk_grid_get_class(sdf, &kind, &background));
    OK(vk_grid_transform(sdf, &h, origin));
    CHECK(kind == VK_GRID_LEVEL_SET && fabs(background - 3 * h) < 1e-6);
    size_t leaves = 0;
    OK(vk_grid_leaf_count(sdf, &leaves));
    CHECK(leaves > 10);
    int32_t *origins = malloc(3 * leaves * sizeof *origins);
    uint64_t *masks = malloc(8 * leaves * sizeof *masks);
    float *values = malloc(512 * leaves * sizeof *values);
    OK(vk_grid_copy_leaves(sdf, 0, leaves, origins, masks));
    OK(vk_grid_copy_values(sdf, 0, leaves, values));
    size_t active = 0, wrong = 0, wrong_sign = 0;
    for (size_t k = 0; k < leaves; k++) {
        for (int n = 0; n < 512; n++) {
            int ijk[3] = {n >> 6, (n >> 3) & 7, n & 7};
            double p[3];
            for (int a = 0; a < 3; a++) p[a] = origin[a] + h * (origins[3 * k + a] + ijk[a]);
            double exact = box_distance(p);
            float v = values[512 * k + n];
            if (masks[8 * k + (n >> 6)] >> (n & 63) & 1) {
                active++;
                wrong += fabs(v - exact) > 1e-5 * (1 + fabs(exact));
            } else {
                /* Beyond the band: the background, signed as the centre lies. */
                wrong_sign += fabs(fabs(v) - background) > 1e-6 || (v < 0) != (exact < 0);
            }
        }
    }
    CHECK(active > 1000 && wrong == 0 && wrong_sign == 0);
    if (wrong || wrong_sign) fprintf(stderr, "%zu of %zu active values wrong, %zu inactive\n", wrong, active, wrong_sign);
    CHECK(vk_grid_copy_values(sdf, leaves, 1, values) == VK_ERROR_INVALID_ARGUMENT);
    free(origins);
    free(masks);
    free(values);
}

/* The solid's leaves and tiles copied out and built again give the same voxels. */
static void check_rebuilt(const vk_grid *solid) {
    size_t leaves = 0, tiles = 0;
    uint64_t voxels = 0, rebuilt_voxels = 0;
    double h = 0, origin[3];
    OK(vk_grid_leaf_count(solid, &leaves));
    OK(vk_grid_tile_count(solid, &tiles));
    OK(vk_grid_voxel_count(solid, &voxels));
    OK(vk_grid_transform(solid, &h, origin));
    CHECK(tiles > 0);
    int32_t *leaf_origins = malloc(3 * leaves * sizeof *leaf_origins);
    uint64_t *masks = malloc(8 * leaves * sizeof *masks);
    int32_t *tile_origins = malloc(3 * tiles * sizeof *tile_origins);
    int32_t *edges = malloc(tiles * sizeof *edges);
    OK(vk_grid_copy_leaves(solid, 0, leaves, leaf_origins, masks));
    OK(vk_grid_copy_tiles(solid, 0, tiles, tile_origins, edges));
    vk_grid *rebuilt = NULL, *difference = NULL;
    OK(vk_grid_from_leaves(h, origin, leaves, leaf_origins, masks, tiles, tile_origins, edges, &rebuilt));
    OK(vk_grid_voxel_count(rebuilt, &rebuilt_voxels));
    CHECK(rebuilt_voxels == voxels);
    OK(vk_grid_combine(rebuilt, solid, VK_DIFFERENCE, 0, &difference));
    uint64_t left = 1;
    OK(vk_grid_voxel_count(difference, &left));
    CHECK(left == 0);
    /* A leaf off the 8-grid and a tile of another edge are refused by name. */
    vk_grid *bad = NULL;
    leaf_origins[0] += 1;
    CHECK(vk_grid_from_leaves(h, origin, 1, leaf_origins, masks, 0, NULL, NULL, &bad) == VK_ERROR_INVALID_ARGUMENT && bad == NULL);
    edges[0] = 16;
    CHECK(vk_grid_from_leaves(h, origin, 0, NULL, NULL, 1, tile_origins, edges, &bad) == VK_ERROR_INVALID_ARGUMENT && bad == NULL);
    OK(vk_grid_free(difference));
    OK(vk_grid_free(rebuilt));
    free(leaf_origins);
    free(masks);
    free(tile_origins);
    free(edges);
}

/* The grids a write makes, as arrays: the level set's fog `density`, then `surface` with its
 * interior as inactive tiles at minus the background and every leaf value within it. */
static void check_export(const vk_grid *sdf) {
    size_t count = 0;
    OK(vk_grid_export_count(sdf, NULL, &count));
    CHECK(count == 2);
    vk_export_info info;
    OK(vk_grid_export_info(sdf, NULL, 0, &info));
    CHECK(strcmp(info.name, "density") == 0 && info.grid_class == VK_CLASS_FOG_VOLUME);
    OK(vk_grid_export_info(sdf, NULL, 1, &info));
    CHECK(strcmp(info.name, "surface") == 0 && info.grid_class == VK_CLASS_LEVEL_SET);
    CHECK(info.value_type == VK_VALUE_FLOAT && info.leaf_count > 0);
    CHECK(!info.tiles_active && info.tile_value == -info.background);
    int32_t *origins = malloc(3 * info.leaf_count * sizeof *origins);
    uint64_t *masks = malloc(8 * info.leaf_count * sizeof *masks);
    float *values = malloc(512 * info.leaf_count * sizeof *values);
    int32_t *tiles = malloc((4 * info.tile_count + 1) * sizeof *tiles);
    OK(vk_grid_export_arrays(sdf, NULL, 1, origins, masks, values, tiles));
    size_t negative = 0;
    for (size_t n = 0; n < 512 * info.leaf_count; n++) {
        CHECK(fabsf(values[n]) <= info.background);
        negative += values[n] < 0;
    }
    CHECK(negative > 0);
    CHECK(vk_grid_export_info(sdf, NULL, 2, &info) == VK_ERROR_INVALID_ARGUMENT);
    free(origins);
    free(masks);
    free(values);
    free(tiles);
}

/* The level set's surface as a mesh: the box's volume, every index a vertex; written by
 * extension, refused by an unknown one. */
static void check_mesh(const vk_grid *sdf, const char *vdb_path) {
    vk_mesh *mesh = NULL;
    OK(vk_grid_to_mesh(sdf, &mesh));
    size_t vertices = 0, triangles = 0;
    OK(vk_mesh_counts(mesh, &vertices, &triangles));
    CHECK(vertices > 100 && triangles > 2 * vertices - 10);
    double *positions = malloc(3 * vertices * sizeof *positions);
    uint32_t *corners = malloc(3 * triangles * sizeof *corners);
    OK(vk_mesh_copy_triangles(mesh, positions, corners));
    double volume = 0;
    for (size_t t = 0; t < triangles; t++) {
        const double *a = positions + 3 * corners[3 * t], *b = positions + 3 * corners[3 * t + 1],
                     *c = positions + 3 * corners[3 * t + 2];
        CHECK(corners[3 * t] < vertices && corners[3 * t + 1] < vertices && corners[3 * t + 2] < vertices);
        volume += (a[0] * (b[1] * c[2] - b[2] * c[1]) - a[1] * (b[0] * c[2] - b[2] * c[0]) +
                   a[2] * (b[0] * c[1] - b[1] * c[0])) / 6.0;
    }
    CHECK(fabs(volume - 2.0) < 0.02);
    free(positions);
    free(corners);
    OK(vk_mesh_free(mesh));
    char path[4096];
    snprintf(path, sizeof path, "%s.ply", vdb_path);
    OK(vk_grid_write_mesh(sdf, path));
    snprintf(path, sizeof path, "%s.txt", vdb_path);
    CHECK(vk_grid_write_mesh(sdf, path) == VK_ERROR_INVALID_ARGUMENT);
    /* Merging the box's flat faces leaves far fewer triangles. */
    vk_options *merge = NULL;
    OK(vk_options_new(&merge));
    CHECK(vk_options_set(merge, "to_mesh", "adaptivity", "-1") == VK_ERROR_INVALID_ARGUMENT);
    CHECK(vk_options_set(merge, "to_mesh", "iso", "0.5") == VK_ERROR_INVALID_ARGUMENT);
    OK(vk_options_set(merge, "to_mesh", "adaptivity", "0.5"));
    OK(vk_grid_to_mesh_with(sdf, merge, &mesh));
    size_t merged_vertices = 0, merged_triangles = 0;
    OK(vk_mesh_counts(mesh, &merged_vertices, &merged_triangles));
    CHECK(merged_triangles > 0 && 3 * merged_triangles < triangles);
    OK(vk_mesh_free(mesh));
    snprintf(path, sizeof path, "%s.merged.ply", vdb_path);
    OK(vk_grid_write_mesh_with(sdf, path, merge));
    OK(vk_options_free(merge));
}

int main(int argc, char **argv) {
    if (argc != 2 && argc != 3) {
        fprintf(stderr, "usage: in_memory LEVEL_SET.vdb [LEVEL_SET.nvdb]\n");
        return 2;
    }
    vk_mesh *m = box();
    vk_options *opts = NULL;
    OK(vk_options_new(&opts));
    OK(vk_options_set_resolution(opts, 40));
    CHECK(vk_options_set_sdf(opts, -1) == VK_ERROR_INVALID_ARGUMENT);
    OK(vk_options_set_sdf(opts, 3.0));
    vk_grid *sdf = NULL, *filled = NULL, *solid = NULL, *carved = NULL;
    OK(vk_voxelize_mesh(m, opts, &sdf));
    check_level_set(sdf);
    check_export(sdf);
    check_mesh(sdf, argv[1]);
    OK(vk_grid_write_vdb(sdf, argv[1]));
    if (argc == 3) {
        OK(vk_grid_write_vdb(sdf, argv[2]));
    }
    /* The level set as a fill: its measures count the centres inside, volume 2. */
    vk_measures measures;
    OK(vk_fill_mesh(m, opts, &filled, &measures));
    CHECK(fabs(measures.volume_inside - 2.0) < 0.02);
    /* A voxel solid, rebuilt from its leaves; less the level set (its inside) it is empty. */
    OK(vk_options_set_sdf(opts, 0));
    OK(vk_fill_mesh(m, opts, &solid, NULL));
    check_rebuilt(solid);
    OK(vk_grid_combine(solid, sdf, VK_DIFFERENCE, 0, &carved));
    uint64_t solid_voxels = 0, carved_voxels = 1;
    OK(vk_grid_voxel_count(solid, &solid_voxels));
    OK(vk_grid_voxel_count(carved, &carved_voxels));
    /* What stays is the surface layer whose centres lie outside the box. */
    CHECK(carved_voxels < solid_voxels / 5);
    vk_grid_class kind = VK_GRID_LEVEL_SET;
    float background = 1;
    OK(vk_grid_get_class(solid, &kind, &background));
    CHECK(kind == VK_GRID_VOXELS && background == 0);
    OK(vk_grid_free(carved));
    OK(vk_grid_free(solid));
    OK(vk_grid_free(filled));
    OK(vk_grid_free(sdf));
    OK(vk_options_free(opts));
    OK(vk_mesh_free(m));
    if (failures == 0) printf("ok\n");
    return failures != 0;
}
