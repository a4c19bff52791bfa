"""The Python API end to end: kinematics (and against Pinocchio), collision, NGIK, optimisers,
roadmaps and planning, and errors."""

import json
import os
from pathlib import Path

import numpy as np
import pytest

import trm

ROOT = Path(__file__).resolve().parents[4]
SPEC = str(ROOT / "specs" / "reach.ron")


@pytest.fixture(scope="module")
def robot():
    return trm.Robot.icub()


def test_fk_is_batch_first_and_agrees_with_one_at_a_time(robot):
    home = robot.posture("home")
    assert home.shape == (robot.dof,) and robot.dof == 41
    poses = robot.fk(home)
    assert poses.shape == (len(robot.link_names), 4, 4)
    rng = np.random.default_rng(0)
    batch = rng.uniform(robot.lower, robot.upper, size=(7, robot.dof))
    many = robot.fk(batch)
    assert many.shape == (7, len(robot.link_names), 4, 4)
    for k in range(7):
        np.testing.assert_array_equal(many[k], robot.fk(batch[k]))
    # a list works as well as an array, and frame_pose of a link is its fk entry
    np.testing.assert_array_equal(robot.fk(list(home)), poses)
    i = robot.link_names.index("r_hand")
    np.testing.assert_allclose(robot.frame_pose(home, "r_hand"), poses[i], atol=1e-12)


def test_jacobian_matches_finite_differences(robot):
    rng = np.random.default_rng(1)
    q = rng.uniform(robot.lower, robot.upper)
    jac = robot.jacobian(q, "r_hand")
    assert jac.shape == (6, robot.dof)
    h = 1e-6
    for k in range(robot.dof):
        dq = np.zeros(robot.dof)
        dq[k] = h
        dp = (robot.frame_pose(q + dq, "r_hand")[:3, 3] - robot.frame_pose(q - dq, "r_hand")[:3, 3]) / (2 * h)
        np.testing.assert_allclose(jac[:3, k], dp, atol=1e-6)
    mass, com = robot.center_of_mass(q)
    assert mass > 1.0 and com.shape == (3,)
    assert robot.com_jacobian(np.stack([q, q])).shape == (2, 3, robot.dof)


def test_fk_matches_pinocchio_on_the_official_icub():
    pin = pytest.importorskip("pinocchio")
    urdf = str(ROOT / "models" / "icub-visuomanip" / "model.urdf")
    ours = trm.Robot.load(urdf)
    model = pin.buildModelFromUrdf(urdf)
    data = model.createData()
    rng = np.random.default_rng(2)
    names = ours.motor_names
    worst = 0.0
    for _ in range(20):
        q = rng.uniform(np.maximum(ours.lower, -3.0), np.minimum(ours.upper, 3.0))
        qp = pin.neutral(model)
        for j in range(1, model.njoints):
            joint = model.joints[j]
            if model.names[j] in names and joint.nq == 1:
                qp[joint.idx_q] = q[names.index(model.names[j])]
        pin.framesForwardKinematics(model, data, qp)
        poses = ours.fk(q)
        for i, link in enumerate(ours.link_names):
            if not model.existFrame(link):
                continue
            expected = data.oMf[model.getFrameId(link)].homogeneous
            worst = max(worst, float(np.abs(poses[i] - expected).max()))
    assert worst < 1e-9, worst


def test_collision_counts_checks_and_pairs(robot):
    col = trm.CollisionModel(robot)
    home = robot.posture("home")
    assert col.count(home) == 0 and col.is_colliding(home) is False
    assert col.min_distance(home) > 0.0
    world = trm.World()
    hand = robot.frame_pose(home, "r_hand")[:3, 3]
    world.add_box("block", [0.1, 0.1, 0.1], list(hand))
    assert world.names == ["block"] and len(world) == 1
    assert col.is_colliding(home, world) is True
    pairs = col.colliding_pairs(home, world)
    assert any(other == "block" and d <= 0.0 for _, other, d in pairs)
    counts = col.count(np.stack([home, home]), world)
    assert counts.shape == (2,) and counts[0] > 0
    world.set_pose("block", [2.0, 0.0, 0.0])
    assert col.count(home, world) == 0


def test_point_clouds_and_meshes_are_obstacles(robot):
    col = trm.CollisionModel(robot)
    home = robot.posture("home")
    hand = robot.frame_pose(home, "r_hand")[:3, 3]
    rng = np.random.default_rng(0)
    cloud = hand + rng.uniform(-0.03, 0.03, size=(500, 3))
    cloud[::50] = np.nan  # a camera's invalid pixels are dropped
    world = trm.World()
    assert world.add_points("scan", cloud, 0.005) == 490
    assert col.is_colliding(home, world) is True
    world.set_pose("scan", [2.0, 0.0, 0.0])
    assert col.is_colliding(home, world) is False
    far = hand + np.array([0.0, 0.0, 1.0])
    fold = np.array([far, far + [0.3, 0, 0], far + [0, 0.3, 0], far + [0.3, 0.3, 0.1]])
    world.add_mesh("fold", fold, [[0, 1, 2], [1, 3, 2]])
    assert col.is_colliding(home, world) is False
    world.set_pose("fold", [0.0, 0.0, -1.0])
    assert col.is_colliding(home, world) is True
    # spheres alone: the hand's place touches the fold's plane, a point far off touches nothing
    spheres = np.array([far + [0.1, 0.1, -0.995], far + [5.0, 0.0, 0.0], cloud[1] + [2.0, 0, 0]])
    assert world.touching(spheres, 0.01) == ["fold", None, "scan"]
    assert world.touching(spheres, 0.0) == [None, None, "scan"]
    with pytest.raises(trm.TrmError, match="centres row 1: .*coordinate 2 of a sphere's centre"):
        world.touching(np.array([far, [0.0, 0.0, np.nan]]), 0.01)
    with pytest.raises(trm.TrmError, match="radius"):
        world.touching(spheres, -0.01)
    with pytest.raises(trm.TrmError, match=r"expected \(N, 3\)"):
        world.add_points("flat", np.zeros((4, 2)), 0.01)
    with pytest.raises(trm.TrmError, match="beyond the 4 given"):
        world.add_mesh("bad", fold, [[0, 1, 9]])


def test_ngik_solves_the_reach_spec_reproducibly():
    problem = trm.Problem.load(SPEC)
    start_cost = problem.cost(problem.start)
    a = problem.solve(seed=3, max_evals=3000)
    b = problem.solve(seed=3, max_evals=3000)
    np.testing.assert_array_equal(a["q"], b["q"])
    assert a["cost"] < start_cost and a["collision_free"]
    assert abs(sum(w * v for _, w, v in a["breakdown"]) - problem.cost(a["q"])) < 1e-9
    assert a["motors"].shape == (41,) and a["q"].shape == (len(problem.active_names),)


HOME_TERM = '        (weight: 0.5, cost: HomePosture(weights: {"torso": 3.0})),\n'


def reach_point_specs(tmp_path):
    """specs/reach_point.ron with its home-posture term moved last (Rust) and removed (for the
    Python twin, which is added last): the terms are summed in the same order."""
    text = (ROOT / "specs" / "reach_point.ron").read_text()
    assert HOME_TERM in text
    without = text.replace(HOME_TERM, "")
    last = without.replace("    ],\n    task:", HOME_TERM + "    ],\n    task:")
    rust, python = tmp_path / "rust.ron", tmp_path / "python.ron"
    rust.write_text(last)
    python.write_text(without)
    return str(rust), str(python)


def test_a_python_cost_inside_ngik_matches_its_rust_twin(tmp_path):
    rust_spec, python_spec = reach_point_specs(tmp_path)
    rust = trm.Problem.load(rust_spec)
    twin = trm.Problem.load(python_spec)
    home = twin.start.copy()
    w = np.array([3.0 if n.startswith("torso") else 1.0 for n in twin.active_names])
    calls = []

    def home_posture(q, frames):
        # HomePosture's formula, summed in its order: sqrt(sum_j (w_j (q_j - home_j))^2)
        calls.append(len(q))
        assert q.shape[1] == len(home) and frames == {}
        s = np.zeros(len(q))
        for j in range(q.shape[1]):
            s = s + (w[j] * (q[:, j] - home[j])) ** 2
        return np.sqrt(s)

    twin.add_cost(home_posture, weight=0.5, label="home posture")
    q = rust.start + 0.05
    assert rust.cost(q) == twin.cost(q)
    a = rust.solve(seed=2, max_evals=2000)
    b = twin.solve(seed=2, max_evals=2000)
    np.testing.assert_array_equal(a["q"], b["q"])
    assert a["cost"] == b["cost"] and a["evaluations"] == b["evaluations"]
    assert [t[0] for t in b["breakdown"]][-1] == "home posture"
    assert len(calls) < b["evaluations"]  # called per batch, not per candidate


def test_python_costs_see_frames_and_their_errors_are_located():
    problem = trm.Problem.load(str(ROOT / "specs" / "reach_point.ron"))
    seen = []

    def low_hand(q, frames):
        hand = frames["r_hand"]
        seen.append(hand.shape)
        return np.maximum(0.0, hand[:, 2, 3] + 0.1) ** 2

    problem.add_cost(low_hand, weight=2.0, label="hand low", frames=["r_hand"])
    start = problem.cost(problem.start)
    assert seen and seen[0][1:] == (4, 4)
    assert problem.solve(seed=1, max_evals=1000)["cost"] < start

    with pytest.raises(trm.TrmError, match="did you mean"):
        problem.add_cost(low_hand, frames=["r_hnd"])
    for bad, message in [
        (lambda q, f: 1 / 0, r"`broken` raised ZeroDivisionError: division by zero \(File .*test_trm.py"),
        (lambda q, f: "cheap", "`broken` returned str"),
        (lambda q, f: np.zeros(len(q) + 1), "`broken` returned shape"),
        (lambda q, f: np.full(len(q), np.nan), "`broken` returned NaN"),
    ]:
        p = trm.Problem.load(str(ROOT / "specs" / "reach_point.ron"))
        p.add_cost(bad, label="broken")
        with pytest.raises(trm.TrmError, match=message):
            p.solve(seed=0, max_evals=500)
        with pytest.raises(trm.TrmError, match=message):
            p.cost(p.start)


@pytest.mark.parametrize("algo", ["xnes", "cmaes"])
def test_optimisers_ask_tell_on_the_sphere(algo):
    opt = trm.Optimizer(algo, np.full(5, 1.0), 0.5, seed=1, max_evals=20_000)
    while not opt.done:
        xs = opt.ask()
        assert xs.ndim == 2 and xs.shape[1] == 5
        opt.tell((xs**2).sum(axis=1))
    assert opt.best_f < 1e-8, (opt.best_f, opt.stop_reasons)
    x, f, n = trm.minimize(lambda x: float((x**2).sum()), np.ones(5), 0.5, algo=algo, seed=1, max_evals=20_000)
    y, g, m = trm.minimize(lambda xs: (xs**2).sum(axis=1), np.ones(5), 0.5, algo=algo, seed=1, max_evals=20_000, batch=True)
    assert f == g and n == m and f < 1e-8
    np.testing.assert_array_equal(x, y)
    assert set(["xnes", "cmaes"]) <= set(trm.ALGORITHMS)


def test_constrained_one_plus_one_keeps_to_the_feasible_side():
    # minimise (x0 − 2)² + x1² subject to x0 ≤ 1, from an infeasible start
    r = trm.minimize_constrained(
        lambda x: float((x[0] - 2.0) ** 2 + x[1] ** 2),
        lambda x: np.array([x[0] - 1.0]),
        [3.0, 1.0],
        0.5,
        seed=2,
        max_evals=4000,
    )
    assert r["feasible"] and r["bootstrap_evaluations"] > 0
    assert r["x"][0] <= 1.0 and abs(r["x"][0] - 1.0) < 1e-3 and abs(r["x"][1]) < 1e-3, r
    with pytest.raises(ZeroDivisionError):
        trm.minimize_constrained(lambda x: 1 / 0, lambda x: [x[0] - 1.0], [0.0, 0.0], 0.5)


def test_view_writes_the_page_and_its_scene(robot, tmp_path):
    home = robot.posture("home")
    lifted = home.copy()
    lifted[robot.motor_names.index("r_shoulder_pitch")] -= 0.5
    world = trm.World()
    world.add_box("table", [0.5, 0.8, 0.04], [-0.4, 0.0, -0.14])
    out = trm.view(robot, str(tmp_path / "scene.html"), frames=np.stack([home, lifted]), world=world,
                   path=[[-0.3, 0.2, 0.0], [-0.3, 0.1, 0.1]])
    assert Path(out).read_text().startswith("<!DOCTYPE html>")
    scene = json.loads((tmp_path / "scene.json").read_text())
    assert len(scene["frames"]) == 2 and len(scene["world"]) == 1 and len(scene["path"]) == 2
    with pytest.raises(trm.TrmError, match="times"):
        trm.view(robot, str(tmp_path / "x.html"), frames=home, times=[0.0, 1.0])


def test_a_page_shows_the_robot_as_it_looks(tmp_path):
    # the Panda's visuals are example-robot-data's COLLADA meshes: drawn in their colours where
    # a package path holds them (TRM_PANDA_VISUALS, as .ci/run sets it), else listed as missing
    robot = trm.Robot.load(str(ROOT / "models" / "panda" / "panda.ron"))
    visuals = os.environ.get("TRM_PANDA_VISUALS")
    trm.view(robot, str(tmp_path / "panda.html"), package_paths=[visuals] if visuals else [])
    scene = json.loads((tmp_path / "panda.json").read_text())
    if visuals:
        assert "missing_visuals" not in scene and len(scene["visuals"]) >= 10
        colours = {tuple(v["color"]) for v in scene["visuals"]}
        assert len(colours) > 2
    else:
        assert len(scene["missing_visuals"]) == 11 and scene["visuals"] == []


def test_a_map_builds_saves_loads_and_plans(tmp_path):
    built = trm.Roadmap.build(SPEC, points=40, seed=0)
    info = built.info()
    # the build stops at the first generation that reaches the target
    assert len(built) >= 40 and info["points"] == len(built) and info["edges"] > 0
    path = tmp_path / "reach.map.json"
    built.save(str(path))
    loaded = trm.Roadmap.load(str(path))
    np.testing.assert_array_equal(loaded.postures, built.postures)
    assert loaded.tasks.shape == (len(built), 3)
    goal = loaded.tasks[len(loaded) // 2]
    plan = trm.Planner(loaded).plan(goal)
    assert plan["positions"].shape[1] == 41 and plan["positions"].shape[0] == plan["times"].shape[0]
    assert np.linalg.norm(plan["task_path"][-1] - goal) < 0.03
    assert plan["times"][0] == 0.0 and np.all(np.diff(plan["times"]) >= 0)
    # a goal that does not fit the task space is named, not searched for
    planner = trm.Planner(loaded)
    with pytest.raises(trm.TrmError, match="the goal point has 2 values; the task space has 3"):
        planner.plan(goal[:2])
    with pytest.raises(trm.TrmError, match=r"the goal point\[1\] is NaN"):
        planner.plan([goal[0], np.nan, goal[2]])
    with pytest.raises(trm.TrmError, match="the goal configuration has 3 values"):
        planner.plan([0.0, 0.0, 0.0], posture=True)
    with pytest.raises(ValueError, match="a task point's motion is timed as it is planned"):
        planner.plan(goal, timed=False)
    # the plan drawn over its map, as `trm plan --view` draws it
    page = trm.view(trm.Robot.icub(), str(tmp_path / "plan.html"),
                    frames=plan["positions"], times=plan["times"], roadmap=loaded)
    scene = json.loads((tmp_path / "plan.json").read_text())
    assert len(scene["map"]["points"]) == len(loaded) and len(scene["map"]["edges"]) == info["edges"]
    assert str(page).endswith("plan.html")


MBM = ROOT / "crates" / "trm-mbm" / "tests" / "fixtures" / "mbm"
PANDA = str(ROOT / "models" / "panda-mbm" / "panda_spherized.ron")


def test_one_robot_planner_answers_moveit_requests_as_the_benchmark_does(tmp_path):
    robot = trm.Robot.load(PANDA)
    requests = sorted(MBM.glob("*/request*.yaml"))
    planner = trm.Planner(robot, request=str(requests[0]))
    assert planner.joint_names == [f"panda_joint{k}" for k in range(1, 8)]
    bench = trm.benchmark_mbm(str(MBM), PANDA)
    expected = {(r["family"], r["index"]): r["outcome"] for r in bench["runs"]}
    for request in requests:
        number = request.stem[len("request"):]
        assert planner.load_scene(str(request.with_name(f"scene{number}.yaml"))) == []
        r = planner.plan_request(str(request))
        same = expected[(request.parent.name, int(number))]
        # a request read once plans the same as its file
        read = trm.MotionPlanRequest.load(str(request))
        assert read.group == "panda_arm" and len(read.goal) == len(read.goal_joints) == 7
        again = planner.plan_request(read)
        np.testing.assert_array_equal(again["waypoints"], r["waypoints"])
        # a certified path (proved free in continuous motion) joins the same ends
        proved = planner.plan_request(read, certified=True)
        np.testing.assert_array_equal(proved["waypoints"][[0, -1]], r["waypoints"][[0, -1]])
        # corner cutting (on by default) never lengthens the greedy shortcut's path
        greedy = planner.plan_request(read, smoothing=0)
        assert r["length"] <= greedy["length"] + 1e-9
        with pytest.raises(OverflowError):
            planner.plan_request(read, smoothing=-1)
        # its goal posed as the hand's pose: IK, then the same planner
        posed = read.to_task_space(robot, "panda_hand")
        assert posed.is_task_space and not read.is_task_space
        reached = planner.plan_request(posed)
        assert planner.is_free(reached["waypoints"][-1]), request
        # the same planner object: the same path, found with the same checks
        assert same["solved"] and r["checks"] == same["checks"], request
        np.testing.assert_array_equal(r["waypoints"], np.array(same["path"]))
        assert r["positions"].shape[1] == 7
        assert r["positions"].shape == r["velocities"].shape == r["accelerations"].shape
        assert r["positions"].shape[0] == r["times"].shape[0]
        np.testing.assert_array_equal(r["positions"][0], r["waypoints"][0])
        np.testing.assert_array_equal(r["positions"][-1], r["waypoints"][-1])
        assert not r["velocities"][-1].any() and not r["velocities"][0].any()
        assert r["times"][0] == 0.0 and np.all(np.diff(r["times"]) > 0)
        assert r["source"] in ("straight", "sampled")
        # the path alone, untimed: the same waypoints, no trajectory
        bare = planner.plan_request(read, timed=False)
        np.testing.assert_array_equal(bare["waypoints"], r["waypoints"])
        assert bare["length"] == r["length"] and bare["checks"] == r["checks"]
        assert not {"times", "positions", "velocities", "motor_names"} & bare.keys()
        alone = planner.plan(r["waypoints"][-1], r["waypoints"][0], timed=False)
        assert "times" not in alone and alone["waypoints"].shape[1] == 7
    assert "7 motors" in repr(planner)
    with pytest.raises(ValueError, match="timed=True"):
        planner.plan_request(str(requests[0]), timed=False, out=tmp_path / "untimed.csv")
    for wrong in ["no", None, 1.5]:
        with pytest.raises(TypeError, match="timed"):
            planner.plan_request(str(requests[0]), timed=wrong)
    assert not (tmp_path / "untimed.csv").exists()
    # timing: MoveIt-like limits, scaled; stopping at every waypoint takes longer
    limits = ROOT / "benches" / "timing" / "panda_joint_limits.yaml"
    planner.set_timing(joint_limits=str(limits), sample_period=0.001)
    blended = planner.plan_request(str(requests[0]))
    acc = np.array([3.75, 1.875, 2.5, 3.125, 3.75, 5.0, 5.0])
    assert np.all(np.abs(blended["accelerations"]) <= acc * (1 + 1e-6))
    planner.set_timing(joint_limits=str(limits), max_deviation=0.0, velocity_scaling=0.5)
    slow = planner.plan_request(str(requests[0]))
    assert slow["times"][-1] > blended["times"][-1]
    planner.set_timing(joint_limits=str(limits), jerk_limited=True, jerk=20.0, sample_period=0.001)
    smooth = planner.plan_request(str(requests[0]))
    jerk = np.diff(smooth["accelerations"], axis=0) / np.diff(smooth["times"])[:, None]
    assert np.all(np.abs(jerk) <= 20.0 * (1 + 1e-6))
    assert smooth["times"][-1] > blended["times"][-1]
    with pytest.raises(ValueError, match="velocity_scaling"):
        planner.set_timing(velocity_scaling=1.5)
    with pytest.raises(ValueError, match="no_such.yaml"):
        planner.set_timing(joint_limits="no_such.yaml")
    # the motion written as `trm plan --out` writes it; a CSV path its JSON would overwrite
    # is refused before planning
    r = planner.plan_request(str(requests[0]), out=tmp_path / "motion.csv")
    names = ["motion.csv", "motion.json", "motion.ros.yaml", "motion.response.yaml"]
    assert [Path(f).name for f in r["files"]] == names
    assert (tmp_path / "motion.csv").read_text().startswith("time,panda_joint1,")
    assert 'group_name: "panda_arm"' in (tmp_path / "motion.response.yaml").read_text()
    with pytest.raises(ValueError, match="out .*m.json is the trajectory CSV's path"):
        planner.plan_request(str(requests[0]), out=tmp_path / "m.json")
    assert not (tmp_path / "m.json").exists()
    (tmp_path / "taken.csv").mkdir()
    for out in ["", tmp_path / "taken.csv"]:
        with pytest.raises(ValueError, match="out|taken.csv"):
            planner.plan_request(str(requests[0]), out=out)
    assert not (tmp_path / "taken.json").exists()


def test_the_python_door_benchmark_runs(capsys, monkeypatch, tmp_path):
    import runpy
    import sys

    csv = tmp_path / "doors.csv"
    monkeypatch.setattr(sys, "argv", ["mbm_planner.py", str(MBM), "--model", PANDA, "--csv", str(csv)])
    runpy.run_path(str(ROOT / "benches" / "python" / "mbm_planner.py"), run_name="__main__")
    out = capsys.readouterr().out
    assert "| all | 14/14 | 14/14 |" in out, out
    assert len(csv.read_text().splitlines()) == 15


def test_the_python_cloud_door_benchmark_runs(capsys, monkeypatch, tmp_path):
    import runpy
    import sys

    # every fixture problem with a cloud as `benchmark-mbm --cloud` writes it: a board of
    # points under the robot's base
    grid = np.stack(np.meshgrid(np.linspace(-0.5, 0.5, 11), np.linspace(-0.5, 0.5, 11)), -1)
    points = np.concatenate([grid.reshape(-1, 2), np.full((121, 1), -0.3)], axis=1)
    lines = ["trm-mbm-problems 1", "robot panda"]
    for family in sorted(p for p in MBM.iterdir() if p.is_dir()):
        for request in sorted(family.glob("request*.yaml")):
            lines += [f"problem {family.name} {int(request.stem[len('request'):])}",
                      "objects 1", f"cloud {len(points)} 0.0025"]
            lines += [" ".join(repr(v) for v in p) for p in points.tolist()]
    peer = tmp_path / "peer-problems.txt"
    peer.write_text("\n".join(lines) + "\n")
    monkeypatch.setattr(sys, "argv", ["mbm_cloud.py", str(MBM), str(peer), "--model", PANDA])
    runpy.run_path(str(ROOT / "benches" / "python" / "mbm_cloud.py"), run_name="__main__")
    out = capsys.readouterr().out
    assert "| all | 14/14 | 14/14 |" in out, out


def test_a_held_object_moves_with_the_hand_and_is_checked(robot):
    joints = ["r_shoulder_pitch", "r_shoulder_roll", "r_elbow"]
    planner = trm.Planner(robot, joints=joints)
    home = robot.posture("home")
    start = np.array([home[robot.motor_names.index(j)] for j in joints])
    goal = start + np.array([-0.6, 0.3, 0.3])
    assert planner.plan(goal, start=start, seed=1)["waypoints"].shape[1] == 3
    # a long bar in the right hand, reaching through the torso: every start collides
    bar = trm.World()
    bar.add_box("bar", [0.05, 0.05, 1.2], [0.0, 0.0, 0.0])
    planner.attach("bar", "r_hand", bar)
    assert planner.attached == ["bar"]
    with pytest.raises(trm.TrmError, match="bar"):
        planner.plan(goal, start=start, seed=1)
    with pytest.raises(trm.TrmError, match="did you mean `bar`"):
        planner.detach("bat")
    planner.detach("bar")
    assert planner.attached == []
    assert planner.plan(goal, start=start, seed=1)["waypoints"].shape[1] == 3
    with pytest.raises(trm.TrmError, match="r_hand"):
        planner.attach("bar", "r_hnd", bar)


def test_a_robot_planner_keeps_experience_across_worlds(robot, tmp_path):
    joints = ["r_shoulder_pitch", "r_shoulder_roll", "r_elbow"]
    planner = trm.Planner(robot, joints=joints, experience=True)
    home = robot.posture("home")
    start = np.array([home[robot.motor_names.index(j)] for j in joints])
    goal = start + np.array([-1.2, 0.6, 0.5])
    world = trm.World()
    world.add_box("pole", [0.04, 0.04, 2.0], [-0.25, 0.3, 0.0])
    planner.world = world
    assert len(planner.world) == 1
    first = planner.plan(goal, start=start, seed=3, max_seconds=10.0)
    assert np.allclose(first["waypoints"][0], start) and np.allclose(first["waypoints"][-1], goal)
    again = planner.plan(goal, start=start, seed=4)
    if first["source"] == "sampled":
        assert planner.num_nodes > 0 and again["source"] == "retrieved"
    # saved, and loaded into another planner of the same motors
    planner.save_experience(str(tmp_path / "arm.experience.json"))
    other = trm.Planner(robot, world, joints=joints, experience=True)
    assert other.load_experience(str(tmp_path / "arm.experience.json")) == len(planner.kept_paths())
    for a, b in zip(other.kept_paths(), planner.kept_paths()):
        np.testing.assert_array_equal(a, b)
    if first["source"] == "sampled":
        assert other.plan(goal, start=start, seed=4)["source"] == "retrieved"
    # forgotten: the next query searches afresh
    other.forget_paths()
    assert other.kept_paths() == [] and other.num_nodes == 0
    assert other.plan(goal, start=start, seed=4)["source"] in ("sampled", "straight")
    with pytest.raises(trm.TrmError, match="the planner moves"):
        trm.Planner(robot, joints=joints[:2]).load_experience(str(tmp_path / "arm.experience.json"))
    # the pole removed: what was found free stays free (a world that adds or moves objects
    # has the kept path checked again)
    planner.world = trm.World()
    assert planner.plan(goal, start=start)["source"] in ("straight", "retrieved", "graph")
    with pytest.raises(trm.TrmError, match="start: give"):
        planner.plan(goal)
    with pytest.raises(trm.TrmError, match="a task point needs a map planner"):
        planner.plan(goal, start=start, posture=False)
    with pytest.raises(trm.TrmError, match="max_seconds"):
        planner.plan(goal, start=start, max_seconds=-1.0)
    with pytest.raises(trm.TrmError, match="joints, posture, request and collision"):
        trm.Planner([], joints=joints)
    with pytest.raises(trm.TrmError, match="nope"):
        trm.Planner(robot, joints=["nope"])
    with pytest.raises(trm.TrmError, match="the goal constrains `panda_joint1`"):
        planner.plan_request(str(sorted(MBM.glob("*/request*.yaml"))[0]))
    with pytest.raises(trm.TrmError, match="give a MotionPlanRequest or a .yaml path"):
        planner.plan_request(3)
    with pytest.raises(trm.TrmError, match="nope.yaml"):
        trm.MotionPlanRequest.load("nope.yaml")


def test_a_map_attached_to_a_robot_planner_is_checked_in_its_world(robot):
    built = trm.Roadmap.build(SPEC, points=20, seed=0)
    planner = trm.Planner(robot)
    assert planner.add_map(built) == len(built) and planner.num_nodes == len(built)
    a, b = built.postures[0], built.postures[len(built) // 2]
    r = planner.plan(b, start=a)
    assert np.allclose(r["waypoints"][0], a) and np.allclose(r["waypoints"][-1], b)
    assert r["source"] in ("straight", "sampled", "graph")
    arm = trm.Planner(robot, joints=["r_shoulder_pitch", "r_shoulder_roll", "r_elbow"])
    with pytest.raises(trm.TrmError, match="differ from the planner's"):
        arm.add_map(built)


def test_a_benchmark_with_a_map_runs_beside_the_plain_one():
    panda_map = trm.Roadmap.build(str(ROOT / "specs" / "panda_reach.ron"), points=10, seed=0)
    r = trm.benchmark_mbm(str(MBM), PANDA, families=["box_panda"], per_family=2, maps=[panda_map])
    assert len(r["with_maps"]) == len(r["runs"]) == 2
    assert all(w["outcome"]["solved"] for w in r["with_maps"])
    assert "With the maps attached" in r["report"]


def test_errors_are_located_trm_errors(robot, tmp_path):
    with pytest.raises(trm.TrmError, match="nope.urdf"):
        trm.Robot.load("nope.urdf")
    with pytest.raises(trm.TrmError, match=r"shape \[3\]"):
        robot.fk(np.zeros(3))
    with pytest.raises(trm.TrmError, match="finite"):
        robot.fk(np.full(robot.dof, np.nan))
    with pytest.raises(trm.TrmError, match="no_such_frame"):
        robot.frame_pose(robot.posture("home"), "no_such_frame")
    bad = tmp_path / "bad.ron"
    bad.write_text(Path(SPEC).read_text().replace("r_palm", "r_plam", 1))
    with pytest.raises(trm.TrmError, match="bad.ron"):
        trm.Problem.load(str(bad))
    with pytest.raises(trm.TrmError):
        trm.Optimizer("no-such-algorithm", np.zeros(2), 1.0)
    assert issubclass(trm.TrmError, ValueError)


def test_the_ompl_comparison_runs(capsys, monkeypatch):
    pytest.importorskip("ompl")
    import runpy
    import sys

    monkeypatch.setattr(sys, "argv", ["ompl_compare.py", "--points", "60", "--time-limit", "2"])
    monkeypatch.setattr("os._exit", lambda code: (_ for _ in ()).throw(SystemExit(code)))
    with pytest.raises(SystemExit) as done:
        runpy.run_path(str(ROOT / "benches" / "python" / "ompl_compare.py"), run_name="__main__")
    assert done.value.code == 0
    out = capsys.readouterr().out
    for planner in ["trm roadmap", "OMPL RRTConnect", "OMPL PRM"]:
        assert f"| {planner}" in out, out


@pytest.mark.parametrize(
    "call, message",
    [
        (lambda r, d: r.fk("abc"), "expected numbers"),
        (lambda r, d: r.fk(np.zeros((2, 2, 41))), "shape"),
        (lambda r, d: trm.view(r, d), "directory"),
        (lambda r, d: trm.view(r, str(Path(d) / "x.html"), path=[[1, 2]]), r"\(K, 3\)"),
        (lambda r, d: trm.Optimizer("xnes", [0, 0], float("nan")), "step size"),
        (lambda r, d: trm.Optimizer("xnes", [0, np.inf], 1.0), "not finite"),
        (lambda r, d: trm.Optimizer("xnes", [], 1.0), "dimension 0"),
        (lambda r, d: trm.minimize_constrained(lambda x: 0.0, lambda x: [0.0], [0, 0], 0.0), "step size"),
        (lambda r, d: trm.Planner([]), "at least one map"),
        (lambda r, d: trm.World().add_box("b", [-1, 1, 1], [0, 0, 0]), "positive"),
        (lambda r, d: trm.World().add_box("b", [1, 1, 1], [np.nan, 0, 0]), "not finite"),
        (lambda r, d: trm.World().remove("zz"), "zz"),
        (lambda r, d: trm.World().add_box("", [1, 1, 1], [0, 0, 0]), "visible character"),
        (lambda r, d: trm.World().add_box(" ", [1, 1, 1], [0, 0, 0]), "visible character"),
        (lambda r, d: trm.Roadmap.load(str(Path(d) / "missing.json")), "missing.json"),
        (lambda r, d: trm.Roadmap.build(SPEC, points=0), "0 points"),
        # round 4 (issue 49): each once accepted without a word
        (lambda r, d: r.fk(np.zeros(41) + 0.5j), "complex values"),
        (lambda r, d: trm.minimize(lambda x: float("nan"), [0, 0], 1.0), r"fun returned nan at x = \["),
        (lambda r, d: trm.Problem.load(SPEC).solve(max_evals=0), "max_evaluations: 0"),
        (lambda r, d: trm.Problem.load(SPEC).clearance(trm.Problem.load(SPEC).start, cap=-0.1), "cap"),
    ],
)
def test_bad_input_is_a_located_error(robot, tmp_path, call, message):
    with pytest.raises(trm.TrmError, match=message):
        call(robot, str(tmp_path))


def test_an_optimiser_refuses_values_for_other_candidates():
    opt = trm.Optimizer("xnes", [0.0, 0.0], 1.0)
    xs = opt.ask()
    with pytest.raises(trm.TrmError, match="fitness values"):
        opt.tell([1.0])
    values = np.ones(len(xs))
    values[2] = np.nan
    with pytest.raises(trm.TrmError, match=r"values\[2\] is NaN"):
        opt.tell(values)
    # inf is a candidate that could not be evaluated: it ranks last
    values[2] = np.inf
    opt.tell(values)
    assert opt.evaluations == len(xs) and opt.best_f == 1.0
    world = trm.World()
    world.add_box("a", [1, 1, 1], [0, 0, 0])
    with pytest.raises(trm.TrmError, match="already exists"):
        world.add_box("a", [1, 1, 1], [0, 0, 0])


def test_worlds_load_from_moveit_scenes(tmp_path):
    scene = ROOT / "crates/trm-mbm/tests/fixtures/mbm/box_panda/scene0001.yaml"
    world = trm.World.load(str(scene))
    assert len(world.names) == 7
    request = ROOT / "crates/trm-mbm/tests/fixtures/mbm/box_panda/request0001.yaml"
    with pytest.raises(trm.TrmError, match="request0001.yaml"):
        trm.World.load(str(request))


# ---- every command of the trm tool from Python ----------------------------------------------


def test_table_iii_from_python_is_seeded_and_complete():
    specs = [str(ROOT / "specs" / "table_iii" / "posture1.ron")]
    kw = dict(algorithms=["xnes", "sir"], runs=2, seed=4, max_evals=1500, no_improvement=1000)
    a = trm.compare_optimisers(specs, **kw)
    b = trm.compare_optimisers(specs, **kw)
    assert [r["cost"] for r in a["runs"]] == [r["cost"] for r in b["runs"]]
    assert len(a["runs"]) == 4 and {r["algorithm"] for r in a["runs"]} == {"xnes", "sir"}
    assert "XNES" in a["table"] and a["csv"].count("\n") == 5
    with pytest.raises(trm.TrmError, match="zigzag"):
        trm.compare_optimisers(specs, algorithms=["zigzag"], runs=1)


def test_motionbenchmaker_from_python_solves_and_verifies():
    fixtures = ROOT / "crates" / "trm-mbm" / "tests" / "fixtures" / "mbm"
    model = str(ROOT / "models" / "panda-mbm" / "panda.ron")
    r = trm.benchmark_mbm(str(fixtures), model, families=["box_panda"], per_family=2, verify=True, certified=True)
    assert len(r["runs"]) == 2 and all(run["family"] == "box_panda" for run in r["runs"])
    for run in r["runs"]:
        assert run["outcome"]["valid"] and run["outcome"]["solved"] and run["verified"] == "proved"
        assert len(run["outcome"]["path"]) >= 2
    assert "box_panda" in r["table"] and r["csv"].startswith("family,problem")
    # the same goals as the hand's pose: IK, then RRT-Connect
    t = trm.benchmark_mbm(str(fixtures), model, families=["box_panda"], per_family=2, verify=True, task_space="panda_hand", certified=True)
    assert all(run["outcome"]["solved"] and run["verified"] == "proved" for run in t["runs"])
    with pytest.raises(trm.TrmError, match="box_panda"):
        trm.benchmark_mbm(str(fixtures), model, families=["box_pand"])
    h = trm.benchmark_mbm(str(fixtures), model, families=["box_panda"], per_family=1, verify=True, sampler="halton", certified=True)
    assert h["runs"][0]["outcome"]["solved"] and h["runs"][0]["verified"] == "proved"
    with pytest.raises(trm.TrmError, match="did you mean `halton`"):
        trm.benchmark_mbm(str(fixtures), model, families=["box_panda"], sampler="halton2")


def small_stick(tmp_path):
    """specs/taskmaps/stick.ron with a thirtieth of its exploration, starting from the grasp its
    random search finds (the search alone takes 35 s in the debug build of the wheel under test)."""
    text = (ROOT / "specs" / "taskmaps" / "stick.ron").read_text()
    assert "iterations: 3000" in text and "restarts: 300" in text and "\n)" in text
    start = "(-0.060737106632267654, -0.06556404763863956, 0.044268289305356916, -0.18850058407328965, -0.1259009170505876, -2.9264430518055624)"
    for full, cut in [("iterations: 3000", "iterations: 100"), ("restarts: 300", "restarts: 10"), ("\n)", f"\n    start: Some({start}),\n)")]:
        text = text.replace(full, cut)
    small = tmp_path / "stick.ron"
    small.write_text(text)
    return str(small)


def test_task_maps_explore_save_load_and_cost(tmp_path):
    explored = trm.TaskMap.explore(small_stick(tmp_path))
    assert len(explored) > 20 and explored.points.shape == (len(explored), 6)
    assert explored.clusters >= 1 and explored.values.shape == (len(explored),)
    explored.save(str(tmp_path / "stick.taskmap.json"))
    back = trm.TaskMap.load(str(tmp_path / "stick.taskmap.json"))
    np.testing.assert_array_equal(back.points, explored.points)
    cost, gradient = back.cost(back.points[3])
    assert cost == 0.0 and gradient.shape == (6,)
    assert back.cost(back.points[3] + 0.05)[0] > 0.0


def test_maps_repair_for_a_new_world_and_run_scenarios():
    built = trm.Roadmap.build(SPEC, points=40, seed=0)
    world = trm.World.load(str(ROOT / "specs" / "worlds" / "reach_with_box.ron"))
    repaired, report = built.repair(world)
    assert report["blocked_nodes"] >= 0 and "stopped_because" in report
    problem = trm.Problem.load(SPEC)
    assert all(problem.is_collision_free(repaired.postures, world))
    run = trm.run_scenario(str(ROOT / "specs" / "scenarios" / "sliding_box.ron"), built, repair_evaluations=300)
    again = trm.run_scenario(str(ROOT / "specs" / "scenarios" / "sliding_box.ron"), built, repair_evaluations=300)
    assert len(run["steps"]) == len(run["times"]) == run["positions"].shape[0] > 10
    assert run["positions"].shape[1] == 41
    assert [s["action"] for s in run["steps"]] == [s["action"] for s in again["steps"]]
    np.testing.assert_array_equal(run["positions"], again["positions"])
    with pytest.raises(trm.TrmError, match="repair_ms"):
        trm.run_scenario(str(ROOT / "specs" / "scenarios" / "sliding_box.ron"), built, repair_ms=0.0)


def test_whole_body_motion_from_python():
    result = trm.stand_up(str(ROOT / "specs" / "wholebody" / "standup.ron"), seed=1, rollouts=6, bootstrap_rollouts=6)
    assert result["rollouts"] >= 6 and isinstance(result["feasible"], bool)
    assert result["solutions"]
    # the budgets given replace the spec's and are checked as the spec's own are
    with pytest.raises(trm.TrmError, match="optimiser.rollouts"):
        trm.stand_up(str(ROOT / "specs" / "wholebody" / "standup.ron"), rollouts=10**8)


def test_reaching_motion_toward_a_task_map_from_python(tmp_path):
    spec = small_stick(tmp_path)
    world = trm.World.load(str(ROOT / "specs" / "worlds" / "table.ron"))
    r = trm.reach_grasp(spec, [-0.3, 0.1, -0.05], world=world, iterations=3)
    assert r["trajectory"].shape[1] == 41 and r["trajectory"].shape[0] > 2
    assert r["final_pose"].shape == (6,) and r["cost"] > 0
    with pytest.raises(trm.TrmError, match="x, y, z"):
        trm.reach_grasp(spec, [0.0, 0.0])


def test_proxies_fitted_from_python_are_written_into_the_urdf(tmp_path):
    fixtures = ROOT / "crates" / "trm-collision" / "tests" / "fixtures" / "meshes"
    mesh = (
        '<collision><geometry><mesh filename="package://demo_pkg/meshes/cube.stl" '
        'scale="0.1 0.2 0.05"/></geometry></collision>'
    )
    urdf = tmp_path / "arm.urdf"
    urdf.write_text(
        f'<robot name="arm"><link name="base">{mesh}</link><link name="tip">{mesh}</link>'
        '<joint name="j" type="revolute"><parent link="base"/><child link="tip"/>'
        '<origin xyz="0 0 0.2"/><axis xyz="0 1 0"/>'
        '<limit lower="-1" upper="1" effort="1" velocity="1"/></joint></robot>'
    )
    out = tmp_path / "arm.fitted.urdf"
    fits = trm.fit_proxies(str(urdf), package_paths=[str(fixtures)], out=str(out))
    assert [f["link"] for f in fits] == ["base", "tip"]
    assert all(f["primitive"] == "box" and f["worst_outside"] <= 1e-9 for f in fits)
    fitted = trm.CollisionModel(trm.Robot.load(str(out)))
    assert len(fitted.body_names) == 2
    # the meshed model itself: its package found through package_paths, as --package-path
    meshed = trm.Robot.load(str(urdf))
    with pytest.raises(trm.TrmError, match="demo_pkg"):
        trm.CollisionModel(meshed)
    assert len(trm.CollisionModel(meshed, package_paths=[fixtures]).body_names) == 2
    with pytest.raises(trm.TrmError, match="no link has mesh collisions"):
        trm.fit_proxies(str(out))


def test_allowed_collisions_generated_from_python_are_seeded():
    collision = trm.CollisionModel(trm.Robot.load(str(ROOT / "models" / "panda" / "panda.ron")))
    a = collision.generate_acm(samples=300, seed=3)
    assert a == collision.generate_acm(samples=300, seed=3)
    assert any(reason == "adjacent" for _, _, reason in a)
    with pytest.raises(trm.TrmError, match="did you mean"):
        collision.generate_acm(samples=10, posture="defualt")


def test_a_benchmark_set_generated_from_python_is_solved_from_python(tmp_path):
    spec = str(ROOT / "specs" / "mbm" / "icub_reach.ron")
    n = trm.generate_mbm(spec, str(tmp_path / "set"), families=["table"], per_family=1, facing=(-1.0, 0.0))
    assert n == 1
    r = trm.benchmark_mbm(str(tmp_path / "set"), "icub_upper_body", per_family=1)
    assert len(r["runs"]) == 1 and r["runs"][0]["outcome"]["valid"]
    with pytest.raises(trm.TrmError, match="facing"):
        trm.generate_mbm(spec, str(tmp_path / "bad"), per_family=1, facing=(0.0, 0.0))


EXAMPLES = sorted((ROOT / "crates" / "trm-py" / "examples").glob("*.py"))


@pytest.mark.parametrize("example", EXAMPLES, ids=lambda p: p.name)
def test_the_examples_run(example):
    import subprocess
    import sys

    done = subprocess.run([sys.executable, str(example)], cwd=ROOT, capture_output=True, text=True, timeout=600)
    assert done.returncode == 0, done.stdout + done.stderr
    assert done.stdout.strip()


def test_there_are_examples():
    assert len(EXAMPLES) >= 3


def test_version_is_the_crate_version():
    cargo = (ROOT / "Cargo.toml").read_text()
    assert f'version = "{trm.__version__}"' in cargo


def test_the_stubs_name_what_the_native_module_has():
    """Every class, function and public member in _trm.pyi exists in the native module, and
    every public name of the module and of its classes is in the stubs."""
    import ast

    native = trm._trm
    stubs = ast.parse((Path(trm.__file__).parent / "_trm.pyi").read_text())
    declared = {}
    for node in stubs.body:
        if isinstance(node, ast.ClassDef):
            declared[node.name] = {
                n.name for n in node.body if isinstance(n, ast.FunctionDef) and not n.name.startswith("_")
            }
        elif isinstance(node, ast.FunctionDef):
            declared[node.name] = None
        elif isinstance(node, ast.AnnAssign) and node.target.id not in ("Array", "ArrayLike"):
            declared[node.target.id] = None
    public = {n for n in dir(native) if not n.startswith("_") or n == "__version__"}
    for name, members in declared.items():
        assert hasattr(native, name), f"the stubs declare trm._trm.{name}, the module lacks it"
        if members is not None:
            actual = {m for m in vars(getattr(native, name)) if not m.startswith("_")}
            assert members == actual, f"trm.{name}: stubs only {members - actual}, module only {actual - members}"
    missing = public - set(declared)
    assert not missing, f"not in the stubs: {missing}"


def test_every_name_has_one_submodule_and_is_at_the_top():
    placed = [name for m in trm.SUBMODULES for name in m.__all__]
    assert len(placed) == len(set(placed)), "a name exported by two submodules"
    native = {n for n in dir(trm._trm) if not n.startswith("_")} - {"TrmError"}
    assert native <= set(placed), f"in no submodule: {native - set(placed)}"
    for m in trm.SUBMODULES:
        for name in m.__all__:
            assert getattr(trm, name) is getattr(m, name), f"trm.{name} is not trm.{m.__name__}.{name}"
    assert set(trm.__all__) == set(placed) | {"__version__", "TrmError"}
    from trm.plan import Planner

    assert Planner is trm.Planner
