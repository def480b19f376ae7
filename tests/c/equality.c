/*
 * The same jobs as the command line's, through the C interface: tests/capi.rs runs this and
 * `voxelkit` on the same inputs and compares voxels and .vdb metadata.
 *
 *   equality MESH.obj CONTROL.obj OUTDIR
 *
 * writes OUTDIR/{mesh,projective,lines,solid,subdiv,implicit,csg}.vdb at resolution 64.
 */
#include <voxelkit.h>

#include <stdio.h>
#include <stdlib.h>

static int check(vk_status status, const char *what) {
    if (status != VK_OK) {
        fprintf(stderr, "%s failed: %s\n", what, vk_last_error());
        exit(1);
    }
    return 0;
}

static void write(vk_grid *grid, const char *dir, const char *name) {
    char path[4096];
    snprintf(path, sizeof path, "%s/%s.vdb", dir, name);
    check(vk_grid_write_vdb(grid, path), name);
}

int main(int argc, char **argv) {
    if (argc != 4) {
        fprintf(stderr, "usage: %s MESH.obj CONTROL.obj OUTDIR\n", argv[0]);
        return 2;
    }
    const char *dir = argv[3];
    vk_options *opts = NULL;
    vk_mesh *mesh = NULL, *control = NULL;
    vk_grid *surface = NULL, *projective = NULL, *lines = NULL, *solid = NULL, *subdiv = NULL,
            *implicit = NULL, *both = NULL;
    check(vk_options_new(&opts), "options");
    check(vk_options_set_resolution(opts, 64), "resolution");
    check(vk_mesh_load(argv[1], &mesh), "mesh");
    check(vk_mesh_load(argv[2], &control), "control mesh");

    check(vk_voxelize_mesh(mesh, opts, &surface), "mesh");
    write(surface, dir, "mesh");
    check(vk_options_set_surface_method(opts, VK_SURFACE_PROJECTIVE), "projective");
    check(vk_voxelize_mesh(mesh, opts, &projective), "projective");
    write(projective, dir, "projective");
    check(vk_voxelize_lines(mesh, opts, &lines), "lines");
    write(lines, dir, "lines");
    check(vk_fill_mesh(mesh, opts, &solid, NULL), "solid");
    write(solid, dir, "solid");
    check(vk_voxelize_subdivision(control, opts, &subdiv), "subdiv");
    write(subdiv, dir, "subdiv");
    const double lo[3] = {-1, -1, -1}, hi[3] = {1, 1, 1};
    check(vk_voxelize_formula("x^2 + y^2 + z^2 - 0.5", VK_CARTESIAN, lo, hi, opts, &implicit),
          "implicit");
    write(implicit, dir, "implicit");
    check(vk_grid_combine(surface, lines, VK_UNION, 0, &both), "csg");
    write(both, dir, "csg");

    vk_grid *grids[] = {surface, projective, lines, solid, subdiv, implicit, both};
    for (size_t i = 0; i < sizeof grids / sizeof grids[0]; i++) check(vk_grid_free(grids[i]), "free");
    check(vk_mesh_free(mesh), "free");
    check(vk_mesh_free(control), "free");
    check(vk_options_free(opts), "free");
    printf("ok\n");
    return 0;
}
