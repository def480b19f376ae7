/*
 * Sets options by name, a line of standard input each: REQUEST<TAB>FIELD<TAB>JSON. Prints
 * "ok" or "error: MESSAGE" for each (tests/capi.rs sends every field of the schema), then
 * makes a surface with the options set and writes it to OUT.vdb with vk_grid_write_vdb_with.
 *
 *   set_options OUT.vdb < lines
 */
#include <voxelkit.h>

#include <stdio.h>
#include <string.h>

int main(int argc, char **argv) {
    if (argc != 2) {
        fprintf(stderr, "usage: %s OUT.vdb < lines\n", argv[0]);
        return 2;
    }
    vk_options *opts = NULL;
    if (vk_options_new(&opts) != VK_OK) return 1;
    char line[4096];
    while (fgets(line, sizeof line, stdin)) {
        line[strcspn(line, "\n")] = '\0';
        char *field = strchr(line, '\t');
        char *value = field ? strchr(field + 1, '\t') : NULL;
        if (!value) {
            fprintf(stderr, "bad line: %s\n", line);
            return 2;
        }
        *field++ = '\0';
        *value++ = '\0';
        if (vk_options_set(opts, line, field, value) == VK_OK) {
            printf("ok\n");
        } else {
            printf("error: %s\n", vk_last_error());
        }
    }
    static const double p[] = {0, 0, 0, 1, 0, 0, 1, 1, 0, 0, 1, 0, 0, 0, 1, 1, 0, 1, 1, 1, 1, 0, 1, 1};
    static const uint32_t t[] = {0, 2, 1, 0, 3, 2, 4, 5, 6, 4, 6, 7, 0, 1, 5, 0, 5, 4,
                                 1, 2, 6, 1, 6, 5, 2, 3, 7, 2, 7, 6, 3, 0, 4, 3, 4, 7};
    vk_mesh *cube = NULL;
    vk_grid *grid = NULL;
    if (vk_mesh_from_triangles(p, 8, t, 12, &cube) != VK_OK ||
        vk_voxelize_mesh(cube, opts, &grid) != VK_OK ||
        vk_grid_write_vdb_with(grid, argv[1], opts) != VK_OK) {
        fprintf(stderr, "%s\n", vk_last_error());
        return 1;
    }
    vk_grid_free(grid);
    vk_mesh_free(cube);
    vk_options_free(opts);
    return 0;
}
