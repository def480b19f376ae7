/*
 * Handles under concurrent misuse: eight threads free one handle at once (exactly one
 * succeeds, nothing is freed twice); a freed handle stays invalid after new objects are made
 * (handles are never reused); an absurd thread count is clamped. Run under valgrind by
 * tests/capi.rs. Exits 0 and prints "ok" when every check holds.
 *
 *   race MESH.obj
 */
#define _POSIX_C_SOURCE 200809L
#include <voxelkit.h>

#include "check.h"

#include <pthread.h>
#include <stdio.h>
#include <string.h>

#define THREADS 8

static vk_mesh *shared_mesh;
static vk_status results[THREADS];
static pthread_barrier_t start;

static void *free_it(void *arg) {
    size_t k = (size_t)arg;
    pthread_barrier_wait(&start);
    results[k] = vk_mesh_free(shared_mesh);
    return NULL;
}

int main(int argc, char **argv) {
    if (argc != 2) {
        fprintf(stderr, "usage: %s MESH.obj\n", argv[0]);
        return 2;
    }
    for (int round = 0; round < 20; round++) {
        CHECK(vk_mesh_load(argv[1], &shared_mesh) == VK_OK);
        pthread_t threads[THREADS];
        pthread_barrier_init(&start, NULL, THREADS);
        for (size_t k = 0; k < THREADS; k++) pthread_create(&threads[k], NULL, free_it, (void *)k);
        for (size_t k = 0; k < THREADS; k++) pthread_join(threads[k], NULL);
        pthread_barrier_destroy(&start);
        int ok = 0;
        for (size_t k = 0; k < THREADS; k++) {
            ok += results[k] == VK_OK;
            CHECK(results[k] == VK_OK || results[k] == VK_ERROR_INVALID_HANDLE);
        }
        CHECK(ok == 1);
    }

    /* A stale handle stays stale when new objects are made. */
    vk_mesh *mesh = NULL, *next = NULL;
    CHECK(vk_mesh_load(argv[1], &mesh) == VK_OK);
    vk_mesh *stale = mesh;
    CHECK(vk_mesh_free(mesh) == VK_OK);
    CHECK(vk_mesh_load(argv[1], &next) == VK_OK);
    CHECK(next != stale);
    size_t vertices = 0, faces = 0;
    CHECK(vk_mesh_counts(stale, &vertices, &faces) == VK_ERROR_INVALID_HANDLE);
    CHECK(vk_mesh_free(stale) == VK_ERROR_INVALID_HANDLE);
    CHECK(vk_mesh_counts(next, &vertices, &faces) == VK_OK && faces > 0);

    /* An absurd thread count is clamped, not obeyed. */
    vk_options *opts = NULL;
    vk_grid *grid = NULL;
    CHECK(vk_options_new(&opts) == VK_OK);
    CHECK(vk_options_set_resolution(opts, 32) == VK_OK);
    CHECK(vk_options_set_threads(opts, 1u << 20) == VK_OK);
    CHECK(vk_voxelize_mesh(next, opts, &grid) == VK_OK);
    CHECK(vk_grid_free(grid) == VK_OK);
    CHECK(vk_options_free(opts) == VK_OK);
    CHECK(vk_mesh_free(next) == VK_OK);

    if (failures == 0) printf("ok\n");
    return failures == 0 ? 0 : 1;
}
