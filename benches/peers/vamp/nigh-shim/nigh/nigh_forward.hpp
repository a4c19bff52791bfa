// A stand-in for the part of Nigh (KavrakiLab's nearest-neighbour library, not reachable from
// this machine) that VAMP's RRT-Connect uses: insert, nearest, size. Nearest is an exhaustive
// scan with VAMP's own distance. For the trees RRT-Connect grows on MotionBenchMaker (tens to a
// few hundred nodes) a scan costs about what Nigh's batched kd-tree does; written for trm's
// side-by-side benchmark only (benches/peers/vamp/README.md).
#pragma once

#include <cstddef>
#include <limits>
#include <optional>
#include <utility>
#include <vector>

namespace unc::robotics::nigh
{
    namespace metric
    {
        template <int p>
        struct LP
        {
        };

        template <typename Type, typename Metric>
        struct Space;
    }  // namespace metric

    struct NoThreadSafety
    {
    };

    template <std::size_t batch = 4>
    struct KDTreeBatch
    {
    };

    template <typename T, typename Space, typename KeyFn, typename Concurrency, typename Strategy>
    class Nigh
    {
        using Key = typename Space::Type;
        using Distance = typename Space::Distance;

        std::vector<T> nodes_;
        KeyFn key_;

    public:
        void insert(const T &node)
        {
            nodes_.push_back(node);
        }

        [[nodiscard]] auto size() const -> std::size_t
        {
            return nodes_.size();
        }

        void clear()
        {
            nodes_.clear();
        }

        [[nodiscard]] auto nearest(const Key &key) const -> std::optional<std::pair<T, Distance>>
        {
            if (nodes_.empty())
            {
                return std::nullopt;
            }
            std::size_t best = 0;
            Distance best_distance = std::numeric_limits<Distance>::infinity();
            for (std::size_t i = 0; i < nodes_.size(); ++i)
            {
                const Distance d = Space::distance(key_(nodes_[i]), key);
                if (d < best_distance)
                {
                    best_distance = d;
                    best = i;
                }
            }
            return std::make_pair(nodes_[best], best_distance);
        }
    };
}  // namespace unc::robotics::nigh
