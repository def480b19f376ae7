// NanoVDB's own headers reading two .nvdb files and comparing them grid by grid: for each grid
// of the first, the grid of the same name in the second has the same type, class, voxel size,
// active voxel count and index box; every voxel of every leaf of either (active or not: a level
// set's inactive voxels keep their sign) has the same state and value in the other; every tile
// of every internal node of either has the same state and value in the other. Each grid must
// also pass NanoVDB's detailed validation (checksum included). Used by tests/nvdb.rs.
//   same_grids OURS.nvdb THEIRS.nvdb  ->  exit 0 and one line per grid, or a message and 1
#include <iostream> // GridValidator.h in NanoVDB 10.0 uses std::cerr without including it
#include <nanovdb/NanoVDB.h>
#include <nanovdb/util/GridValidator.h>
#include <nanovdb/util/IO.h>

#include <cstdio>
#include <string>

namespace {

template <typename T>
bool same(const T& a, const T& b) { return a == b; }
bool same(const nanovdb::Vec3f& a, const nanovdb::Vec3f& b)
{
    return a[0] == b[0] && a[1] == b[1] && a[2] == b[2];
}

// Every voxel of every leaf of `a` and every tile of its internal nodes, looked up in `b`.
template <typename T>
bool covered(const nanovdb::NanoGrid<T>& a, const nanovdb::NanoGrid<T>& b, const char* which)
{
    auto acc = b.getAccessor();
    const auto& tree = a.tree();
    bool ok = true;
    auto check = [&](const nanovdb::Coord& ijk, bool active, const T& value) {
        if (ok && (acc.isActive(ijk) != active || !same(acc.getValue(ijk), value))) {
            std::fprintf(stderr, "%s: grid %s differs at (%d, %d, %d)\n", which, a.gridName(),
                         ijk[0], ijk[1], ijk[2]);
            ok = false;
        }
    };
    for (uint32_t i = 0; ok && i < tree.nodeCount(0); ++i) {
        const auto& leaf = tree.template getFirstNode<0>()[i];
        for (uint32_t n = 0; n < 512; ++n) {
            const auto ijk = leaf.offsetToGlobalCoord(n);
            check(ijk, leaf.isActive(ijk), leaf.getValue(ijk));
        }
    }
    auto tiles = [&](const auto* nodes, uint32_t count) {
        for (uint32_t i = 0; ok && i < count; ++i) {
            const auto& node = nodes[i];
            for (uint32_t n = 0; n < node.SIZE; ++n) {
                if (node.childMask().isOn(n)) continue;
                const auto ijk = node.offsetToGlobalCoord(n);
                check(ijk, node.isActive(ijk), node.getValue(ijk));
            }
        }
    };
    tiles(tree.template getFirstNode<1>(), tree.nodeCount(1));
    tiles(tree.template getFirstNode<2>(), tree.nodeCount(2));
    return ok;
}

template <typename T>
bool compare(const nanovdb::GridHandle<>& ours, const nanovdb::GridHandle<>& theirs)
{
    const auto* a = ours.grid<T>();
    const auto* b = theirs.grid<T>();
    if (!b) {
        std::fprintf(stderr, "grid %s: the second file's grid has another type\n", a->gridName());
        return false;
    }
    if (!nanovdb::isValid(*a, true, true)) {
        std::fprintf(stderr, "grid %s: NanoVDB's validation fails\n", a->gridName());
        return false;
    }
    const bool same_header = a->gridClass() == b->gridClass() &&
                             a->activeVoxelCount() == b->activeVoxelCount() &&
                             a->indexBBox() == b->indexBBox() &&
                             std::abs(a->voxelSize()[0] - b->voxelSize()[0]) <= 1e-12 * b->voxelSize()[0];
    if (!same_header) {
        std::fprintf(stderr, "grid %s: class, voxel count (%llu, %llu), box or voxel size differ\n",
                     a->gridName(), (unsigned long long)a->activeVoxelCount(),
                     (unsigned long long)b->activeVoxelCount());
        return false;
    }
    if (!covered(*a, *b, "first in second") || !covered(*b, *a, "second in first")) return false;
    std::printf("%s %s %llu voxels, %u leaves: same\n", a->gridName(),
                nanovdb::toStr(a->gridType()), (unsigned long long)a->activeVoxelCount(),
                a->tree().nodeCount(0));
    return true;
}

} // namespace

int main(int argc, char** argv)
{
    if (argc != 3) {
        std::fprintf(stderr, "usage: same_grids OURS.nvdb THEIRS.nvdb\n");
        return 2;
    }
    try {
        const auto ours = nanovdb::io::readGrids(argv[1]);
        if (ours.empty()) {
            std::fprintf(stderr, "%s holds no grids\n", argv[1]);
            return 1;
        }
        for (const auto& handle : ours) {
            const std::string name = handle.gridMetaData()->shortGridName();
            const auto theirs = nanovdb::io::readGrid(argv[2], name);
            if (!theirs) {
                std::fprintf(stderr, "%s has no grid %s\n", argv[2], name.c_str());
                return 1;
            }
            bool ok = false;
            switch (handle.gridType()) {
            case nanovdb::GridType::Float: ok = compare<float>(handle, theirs); break;
            case nanovdb::GridType::Vec3f: ok = compare<nanovdb::Vec3f>(handle, theirs); break;
            case nanovdb::GridType::Boolean: ok = compare<bool>(handle, theirs); break;
            default: std::fprintf(stderr, "grid %s: unexpected type\n", name.c_str());
            }
            if (!ok) return 1;
        }
    } catch (const std::exception& e) {
        std::fprintf(stderr, "%s\n", e.what());
        return 1;
    }
    return 0;
}
