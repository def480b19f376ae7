/* The C tests' checks: a failed one prints where and the library's last error, and counts. */
#pragma once
#include <stdio.h>
#include <voxelkit.h>

static int failures = 0;

#define CHECK(cond)                                                                      \
    do {                                                                                 \
        if (!(cond)) {                                                                   \
            fprintf(stderr, "%s:%d: check failed: %s (last error: %s)\n", __FILE__,      \
                    __LINE__, #cond, vk_last_error());                                   \
            failures++;                                                                  \
        }                                                                                \
    } while (0)

#define OK(call) CHECK((call) == VK_OK)
