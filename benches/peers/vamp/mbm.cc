// VAMP's RRT-Connect and simplifier on MotionBenchMaker problems exported by trm
// (`cargo xtask benchmark-mbm SET --model M --vamp target/peers/vamp-mbm`), for the side-by-side
// table. Reads the problems on stdin (the format `trm_plan::mbm::peer_problems` writes), prints
// one line per problem on stdout (after `robot NAME`, `configurations N` instead of `joints`
// times FK + self-collision of N configurations instead, and `scenes` FK + collision in
// scenes: see `configurations` and `scenes` below):
//   result FAMILY INDEX VALID SOLVED PLAN_NS SIMPLIFY_NS COST SIMPLIFIED_COST ITERATIONS WAYPOINTS BUILD_NS
//   path q1 … qd   (one line per waypoint of the simplified path)
// Settings as VAMP's own evaluate_mbm.py: Halton sampler reset per problem, dynamic-domain
// RRT-Connect with the robot's range, default simplification, rake = the CPU's float lanes.
// Built by benches/peers/vamp/build.sh; see README.md there.
#include <chrono>
#include <cstdio>
#include <iostream>
#include <memory>
#include <sstream>
#include <string>
#include <vector>

#include <vamp/collision/factory.hh>
#include <vamp/planning/rrtc.hh>
#include <vamp/planning/simplify.hh>
#include <vamp/planning/validate.hh>
#include <vamp/random/halton.hh>
#include <vamp/robots/baxter.hh>
#include <vamp/robots/fetch.hh>
#include <vamp/robots/panda.hh>
#include <vamp/robots/ur5.hh>

namespace
{
    constexpr std::size_t rake = vamp::FloatVectorWidth;

    [[noreturn]] void fail(const std::string &what)
    {
        std::cerr << "vamp-mbm: " << what << '\n';
        std::exit(2);
    }

    auto expect(std::istream &in, const std::string &word) -> void
    {
        std::string got;
        if (!(in >> got) || got != word)
        {
            fail("expected `" + word + "`, read `" + got + "`");
        }
    }

    template <typename T>
    auto read(std::istream &in, const char *what) -> T
    {
        T value{};
        if (!(in >> value))
        {
            fail(std::string("could not read ") + what);
        }
        return value;
    }

    // three numbers in order (a constructor's arguments may be evaluated in any order)
    auto read_vector(std::istream &in) -> Eigen::Vector3f
    {
        Eigen::Vector3f v;
        for (int i = 0; i < 3; ++i)
        {
            v[i] = read<float>(in, "a coordinate");
        }
        return v;
    }

    // Cylinders as VAMP's own MotionBenchMaker loader (vamp.problem_dict_to_vamp) gives them:
    // capsules (VAMP's checks never read Environment::cylinders), and in the `box` family,
    // whose goals grasp a can from above, boxes of half extents (r, r, length / 2).
    // A point cloud (`cloud N RADIUS` and N lines `x y z`) becomes VAMP's CAPT for the robot's
    // sphere radii [r_min, r_max], as its evaluate_mbm.py --pointcloud builds it; `build_ns`
    // adds the time building it took.
    auto read_environment(
        std::istream &in,
        bool cylinders_as_boxes,
        float r_min,
        float r_max,
        std::size_t &build_ns) -> vamp::collision::Environment<float>
    {
        vamp::collision::Environment<float> environment;
        expect(in, "objects");
        const auto n = read<std::size_t>(in, "the object count");
        for (std::size_t i = 0; i < n; ++i)
        {
            const auto kind = read<std::string>(in, "an object kind");
            if (kind == "cloud")
            {
                const auto count = read<std::size_t>(in, "the point count");
                const auto radius = read<float>(in, "the point radius");
                std::vector<vamp::collision::Point> points(count);
                for (auto &q : points)
                {
                    const auto v = read_vector(in);
                    q = {v[0], v[1], v[2]};
                }
                const auto began = std::chrono::steady_clock::now();
                environment.pointclouds.emplace_back(points, r_min, r_max, radius);
                build_ns += static_cast<std::size_t>(
                    std::chrono::duration<double, std::nano>(std::chrono::steady_clock::now() - began).count());
                continue;
            }
            const auto p = read_vector(in);
            if (kind == "sphere")
            {
                environment.spheres.emplace_back(
                    vamp::collision::factory::sphere::array({p[0], p[1], p[2]}, read<float>(in, "radius")));
                continue;
            }
            const auto w = read<float>(in, "qw");
            const auto x = read<float>(in, "qx");
            const auto y = read<float>(in, "qy");
            const auto z = read<float>(in, "qz");
            // VAMP's factories take Euler angles applied as Rz(phi) Ry(theta) Rx(rho) (the
            // "sxyz" angles its Python loader computes); its eigen_rot helpers take
            // eulerAngles(0, 1, 2), the X-Y-Z product, which differs for general rotations.
            const auto zyx = Eigen::Quaternionf(w, x, y, z).normalized().toRotationMatrix().eulerAngles(2, 1, 0);
            const Eigen::Vector3f euler(zyx[2], zyx[1], zyx[0]);
            if (kind == "box")
            {
                const auto h = read_vector(in);
                environment.cuboids.emplace_back(vamp::collision::factory::cuboid::eigen(p, euler, h));
            }
            else if (kind == "cylinder")
            {
                const auto radius = read<float>(in, "radius");
                const auto length = read<float>(in, "length");
                if (cylinders_as_boxes)
                {
                    environment.cuboids.emplace_back(vamp::collision::factory::cuboid::eigen(
                        p, euler, Eigen::Vector3f(radius, radius, length / 2)));
                }
                else
                {
                    environment.capsules.emplace_back(
                        vamp::collision::factory::capsule::center::eigen(p, euler, radius, length));
                }
            }
            else
            {
                fail("unknown object kind `" + kind + "`");
            }
        }
        environment.sort();
        return environment;
    }

    // `N NAME…` after `joints`: VAMP's joints of the robot, in its order.
    template <typename Robot>
    auto expect_joints(std::istream &in) -> void
    {
        if (read<std::size_t>(in, "the joint count") != Robot::dimension)
        {
            fail(std::string("joint count differs from VAMP's ") + Robot::name);
        }
        for (std::size_t j = 0; j < Robot::dimension; ++j)
        {
            const auto name = read<std::string>(in, "a joint name");
            if (name != Robot::joint_names[j])
            {
                fail("joint " + std::to_string(j) + " is `" + name + "`, VAMP's is `" +
                     std::string(Robot::joint_names[j]) + "`");
            }
        }
    }

    // `count` configurations of the robot, one per line, in VAMP's joint order.
    template <typename Robot>
    auto read_configurations(std::istream &in, std::size_t count)
        -> std::vector<std::array<float, Robot::dimension>>
    {
        std::vector<std::array<float, Robot::dimension>> qs(count);
        for (auto &q : qs)
        {
            for (auto &v : q)
            {
                v = read<float>(in, "a joint value");
            }
        }
        return qs;
    }

    // Blocks of `rake` configurations (lane l: configuration first + l, the last repeated
    // past the end; with `broadcast`, configuration `first` in every lane).
    template <typename Robot>
    auto block_of(const std::vector<std::array<float, Robot::dimension>> &qs, std::size_t first, bool broadcast)
        -> typename Robot::template ConfigurationBlock<rake>
    {
        typename Robot::template ConfigurationBlock<rake> block;
        for (std::size_t j = 0; j < Robot::dimension; ++j)
        {
            std::array<float, rake> lane{};
            for (std::size_t l = 0; l < rake; ++l)
            {
                const auto k = broadcast ? first : std::min(first + l, qs.size() - 1);
                lane[l] = qs[k][j];
            }
            block[j] = vamp::FloatVector<rake>(lane);
        }
        return block;
    }

    template <typename Robot>
    auto run(std::istream &in, float range) -> void
    {
        using Configuration = typename Robot::Configuration;
        using Environment = vamp::collision::Environment<vamp::FloatVector<rake>>;
        using RRTC = vamp::planning::RRTC<Robot, rake, Robot::resolution>;

        expect_joints<Robot>(in);
        expect(in, "problems");
        const auto count = read<std::size_t>(in, "the problem count");

        vamp::planning::RRTCSettings settings;
        settings.range = range;
        settings.max_iterations = 1000000;
        settings.max_samples = 1000000;
        const vamp::planning::SimplifySettings simplify_settings;
        auto rng = std::make_shared<vamp::rng::Halton<Robot>>();

        const auto configuration = [&in](const char *what)
        {
            expect(in, what);
            typename Robot::ConfigurationArray q;
            for (auto &v : q)
            {
                v = read<float>(in, what);
            }
            return Configuration(q);
        };

        for (std::size_t k = 0; k < count; ++k)
        {
            expect(in, "problem");
            const auto family = read<std::string>(in, "a family");
            const auto index = read<std::size_t>(in, "an index");
            const auto start = configuration("start");
            const auto goal = configuration("goal");
            const bool box_family = family.rfind("box_", 0) == 0 or family == "box";
            std::size_t build_ns = 0;
            const Environment environment(
                read_environment(in, box_family, Robot::min_radius, Robot::max_radius, build_ns));

            const bool valid = vamp::planning::validate_motion<Robot, rake, 1>(start, start, environment) and
                               vamp::planning::validate_motion<Robot, rake, 1>(goal, goal, environment);
            std::printf("result %s %zu %d", family.c_str(), index, valid ? 1 : 0);
            if (not valid)
            {
                std::printf(" 0 0 0 0 0 0 0 %zu\n", build_ns);
                continue;
            }
            rng->reset();
            const auto result = RRTC::solve(start, goal, environment, settings, rng);
            if (result.path.empty())
            {
                std::printf(" 0 %zu 0 0 0 %zu 0 %zu\n", result.nanoseconds, result.iterations, build_ns);
                continue;
            }
            const auto simple = vamp::planning::simplify<Robot, rake, Robot::resolution>(
                result.path, environment, simplify_settings, rng);
            std::printf(
                " 1 %zu %zu %.6f %.6f %zu %zu %zu\n",
                result.nanoseconds,
                simple.nanoseconds,
                result.path.cost(),
                simple.path.cost(),
                result.iterations,
                simple.path.size(),
                build_ns);
            for (const auto &q : simple.path)
            {
                const auto a = q.to_array();
                std::printf("path");
                for (std::size_t j = 0; j < Robot::dimension; ++j)
                {
                    std::printf(" %.9g", a[j]);
                }
                std::printf("\n");
            }
        }
    }

    // Configurations mode: FK + self-collision of each configuration in an empty world, timed
    // over blocks of `rake` configurations (VAMP's fkcc), and each one's verdict alone.
    template <typename Robot>
    auto configurations(std::istream &in) -> void
    {
        using Block = typename Robot::template ConfigurationBlock<rake>;
        const vamp::collision::Environment<vamp::FloatVector<rake>> empty{};
        const auto n = read<std::size_t>(in, "the configuration count");
        const auto qs = read_configurations<Robot>(in, n);
        std::vector<Block> blocks;
        for (std::size_t first = 0; first < n; first += rake)
        {
            blocks.push_back(block_of<Robot>(qs, first, false));
        }
        const auto repeats = read<std::size_t>(in, "the repeat count");
        for (std::size_t r = 0; r < repeats; ++r)
        {
            std::size_t valid = 0;
            const auto began = std::chrono::steady_clock::now();
            for (auto &block : blocks)
            {
                valid += Robot::template fkcc<rake>(empty, block) ? 1 : 0;
            }
            const auto ns = std::chrono::duration<double, std::nano>(std::chrono::steady_clock::now() - began).count();
            std::printf("time %.3f %zu\n", ns / static_cast<double>(n), valid);
            std::fflush(stdout);
            // wait for the caller's turn (interleaved runs): one word per repeat
            if (r + 1 < repeats)
            {
                expect(in, "next");
            }
        }
        for (std::size_t k = 0; k < n; ++k)
        {
            auto block = block_of<Robot>(qs, k, true);
            std::printf("valid %d\n", Robot::template fkcc<rake>(empty, block) ? 1 : 0);
        }
    }

    // Scenes mode: FK + collision (self and world) of configurations in several scenes, each
    // scene's blocks of `rake` timed apart, round by round (`next` starts each round), then how many of each scene's configurations VAMP finds free, one at a time:
    //   scenes, joints N NAME…, K, then K times: scene FAMILY, objects … (as a problem's),
    //   configurations N and N lines; then rounds R. Prints `round T1/B1 … TK/BK` (ns per
    //   configuration / free blocks) per round and `free F1 … FK` (free configurations).
    template <typename Robot>
    auto scenes(std::istream &in) -> void
    {
        using Block = typename Robot::template ConfigurationBlock<rake>;
        using Environment = vamp::collision::Environment<vamp::FloatVector<rake>>;
        expect(in, "joints");
        expect_joints<Robot>(in);
        const auto count = read<std::size_t>(in, "the scene count");
        std::vector<Environment> environments;
        std::vector<std::vector<std::array<float, Robot::dimension>>> configurations;
        std::vector<std::vector<Block>> blocks(count);
        for (std::size_t k = 0; k < count; ++k)
        {
            expect(in, "scene");
            const auto family = read<std::string>(in, "a family");
            const bool box_family = family.rfind("box_", 0) == 0 or family == "box";
            std::size_t build_ns = 0;
            environments.emplace_back(
                read_environment(in, box_family, Robot::min_radius, Robot::max_radius, build_ns));
            expect(in, "configurations");
            const auto n = read<std::size_t>(in, "the configuration count");
            configurations.push_back(read_configurations<Robot>(in, n));
            for (std::size_t first = 0; first < n; first += rake)
            {
                blocks[k].push_back(block_of<Robot>(configurations[k], first, false));
            }
        }
        expect(in, "rounds");
        const auto rounds = read<std::size_t>(in, "the round count");
        for (std::size_t r = 0; r < rounds; ++r)
        {
            // each round when the caller says so: never while the caller times its own
            expect(in, "next");
            std::printf("round");
            for (std::size_t k = 0; k < count; ++k)
            {
                std::size_t valid = 0;
                const auto began = std::chrono::steady_clock::now();
                for (auto &block : blocks[k])
                {
                    valid += Robot::template fkcc<rake>(environments[k], block) ? 1 : 0;
                }
                const auto ns =
                    std::chrono::duration<double, std::nano>(std::chrono::steady_clock::now() - began).count();
                const auto n = std::max<std::size_t>(configurations[k].size(), 1);
                // (the count of free blocks is printed so that no compiler drops the checks)
                std::printf(" %.3f/%zu", ns / static_cast<double>(n), valid);
            }
            std::printf("\n");
            std::fflush(stdout);
        }
        std::printf("free");
        for (std::size_t k = 0; k < count; ++k)
        {
            std::size_t free = 0;
            for (std::size_t i = 0; i < configurations[k].size(); ++i)
            {
                auto block = block_of<Robot>(configurations[k], i, true);
                free += Robot::template fkcc<rake>(environments[k], block) ? 1 : 0;
            }
            std::printf(" %zu", free);
        }
        std::printf("\n");
        std::fflush(stdout);
    }
}  // namespace

namespace
{
    template <typename Robot>
    auto dispatch(std::istream &in, float range) -> void
    {
        std::string mode;
        in >> mode;
        if (mode == "joints")
        {
            run<Robot>(in, range);
        }
        else if (mode == "configurations")
        {
            configurations<Robot>(in);
        }
        else if (mode == "scenes")
        {
            scenes<Robot>(in);
        }
        else
        {
            fail("expected `joints`, `configurations` or `scenes`, read `" + mode + "`");
        }
    }
}  // namespace

auto main() -> int
{
    std::ios::sync_with_stdio(false);
    expect(std::cin, "trm-mbm-problems");
    if (read<int>(std::cin, "the format version") != 1)
    {
        fail("format version is not 1");
    }
    expect(std::cin, "robot");
    const auto robot = read<std::string>(std::cin, "the robot name");
    // RRT-Connect ranges of VAMP's evaluate_mbm.py (vamp/constants.py)
    if (robot == "panda")
    {
        dispatch<vamp::robots::Panda>(std::cin, 1.0F);
    }
    else if (robot == "fetch")
    {
        dispatch<vamp::robots::Fetch>(std::cin, 1.0F);
    }
    else if (robot == "ur5")
    {
        dispatch<vamp::robots::UR5>(std::cin, 1.5F);
    }
    else if (robot == "baxter")
    {
        dispatch<vamp::robots::Baxter>(std::cin, 0.5F);
    }
    else
    {
        fail("VAMP has no robot `" + robot + "` here (panda, fetch, ur5, baxter)");
    }
    return 0;
}
