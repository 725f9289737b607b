import numpy as np
from rosbags.typesys import Stores


def _cosim_store():
    from rosbags.typesys import get_typestore
    from rosbags.typesys.msg import get_types_from_msg

    import cosim.core.messages as messages

    store = get_typestore(Stores.ROS2_JAZZY)
    declared = [getattr(messages, n) for n in messages.__all__]
    for cls in declared:
        wire = getattr(cls, "wire", None)
        if wire is None or wire.ros_type.split("/")[0] != "cosim_msgs":
            continue
        for kind in [*wire.dependencies(), wire]:
            if kind.ros_type not in store.fielddefs:
                store.register(get_types_from_msg(kind.msg_text(), kind.ros_type))
    return store


COSIM = _cosim_store()


def _size(name, **fields):
    return len(COSIM.serialize_cdr(COSIM.types[name](**fields), name))


def _hdr(stamp_ns=5, frame="map"):
    time = COSIM.types["builtin_interfaces/msg/Time"](sec=0, nanosec=stamp_ns)
    return COSIM.types["std_msgs/msg/Header"](stamp=time, frame_id=frame)


def test_project_message_sizes_match_their_msg_definitions():
    from cosim.core.messages import (
        CbbaBids,
        NavGoal,
        NavStatus,
        RobotState,
        ServiceReply,
        ServiceRequest,
        SimplexBasis,
        TaskClaim,
        TaskDone,
        TaskInfo,
        TaskOrder,
        TaskSet,
    )

    def info(t):
        return COSIM.types["cosim_msgs/msg/TaskInfo"](
            task_id=t.task_id, x=t.x_m, y=t.y_m, eligible=list(t.eligible), holder=t.holder
        )

    def column(c):
        return COSIM.types["cosim_msgs/msg/SimplexColumn"](
            kind=c[0], robot=c[1], task=c[2], cost=c[3]
        )

    tasks = (TaskInfo(3, 1.0, 2.0, ("robot_1", "robot_12"), "robot_1"), TaskInfo(7, 5.0, 6.0, ()))
    columns = ((0, 1, 2, 3.5), (1, 2, -1, 0.0), (2, -1, 4, 1e6))
    cases = [
        (NavGoal(5, 4, 1.0, 2.0), dict(header=_hdr(), goal_id=4, x=1.0, y=2.0, yaw=0.0)),
        (
            NavStatus(5, 4, "progress", 1.0, 2.0, 3.0),
            dict(header=_hdr(), goal_id=4, state="progress", x=1.0, y=2.0, remaining=3.0),
        ),
        (
            RobotState(5, "robot_3", 1.0, 2.0, 0.1, 0.5, 0.33),
            dict(header=_hdr(), robot="robot_3", x=1.0, y=2.0, yaw=0.1, v=0.5, radius=0.33),
        ),
        (TaskSet(5, 2, tasks), dict(header=_hdr(), epoch=2, tasks=[info(t) for t in tasks])),
        (
            TaskClaim(5, 2, 3, "robot_1", 4.5, "release"),
            dict(header=_hdr(), epoch=2, task_id=3, robot="robot_1", cost=4.5, state="release"),
        ),
        (ServiceRequest(5, 3, "robot_1"), dict(header=_hdr(), task_id=3, robot="robot_1")),
        (
            ServiceReply(5, 3, "robot_1", True),
            dict(header=_hdr(), task_id=3, robot="robot_1", granted=True),
        ),
        (TaskDone(5, 3, "robot_10"), dict(header=_hdr(), task_id=3, robot="robot_10")),
        (
            SimplexBasis(5, 2, "robot_1", 7, columns),
            dict(
                header=_hdr(),
                epoch=2,
                robot="robot_1",
                round=7,
                columns=[column(c) for c in columns],
            ),
        ),
        (
            CbbaBids(5, 2, "robot_1", (1.0, 2.0, 3.0), (0, -1, 2)),
            dict(
                header=_hdr(),
                epoch=2,
                robot="robot_1",
                bids=np.array([1.0, 2.0, 3.0]),
                winners=np.array([0, -1, 2], dtype=np.int32),
            ),
        ),
        (
            TaskOrder(5, 2, "robot_1", -1, 0.0),
            dict(header=_hdr(), epoch=2, robot="robot_1", task_id=-1, cost=0.0),
        ),
    ]
    for message, fields in cases:
        assert message.size_bytes() == _size(message.ros_type, **fields), message.ros_type
