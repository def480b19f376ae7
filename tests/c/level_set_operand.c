/*
 * A level set read through the C interface stands for its inside: tests/capi.rs writes
 * OpenVDB's own level-set sphere and a solid box around it, and compares what this prints.
 *
 *   level_set_operand BOX.vdb SPHERE.vdb
 *
 * prints the voxels of the box and of the box less the sphere (its second grid resampled).
 */
#include <voxelkit.h>

#include <inttypes.h>
#include <stdio.h>
#include <stdlib.h>

static void check(vk_status status, const char *what) {
    if (status != VK_OK) {
        fprintf(stderr, "%s failed: %s\n", what, vk_last_error());
        exit(1);
    }
}

int main(int argc, char **argv) {
    if (argc != 3) {
        fprintf(stderr, "usage: %s BOX.vdb SPHERE.vdb\n", argv[0]);
        return 2;
    }
    vk_grid *box = NULL, *sphere = NULL, *cut = NULL;
    check(vk_grid_read_vdb(argv[1], "density", &box), "the box");
    check(vk_grid_read_vdb(argv[2], NULL, &sphere), "the sphere");
    check(vk_grid_combine(box, sphere, VK_DIFFERENCE, 1, &cut), "the difference");
    uint64_t whole = 0, left = 0;
    check(vk_grid_voxel_count(box, &whole), "count");
    check(vk_grid_voxel_count(cut, &left), "count");
    printf("%" PRIu64 " %" PRIu64 "\n", whole, left);
    vk_grid_free(cut);
    vk_grid_free(sphere);
    vk_grid_free(box);
    return 0;
}
