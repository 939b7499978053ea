"""`frog-bt run`'s executive against `frog-bt sim` on sim time: whole tours, exact commands."""

from __future__ import annotations

from tour import tour

RECRUIT_7 = ["/ApproachPeopleFar 7", "/ICL_command start", "/ICL_command stop"]
FACES = ["/ICL_command start", "/ICL_command stop"]
STORY = ("tour", "start_introduction", "ask_tour", "start_poi", "finish_poi")
AFTER_RECRUIT = [
    "/GotoWayPoint POI3",
    "/GotoWayPoint POI4",
    "/GotoWayPoint POI5",
    "/GotoWayPoint TEMP",
    "/GotoWayPoint END",
    "/GotoWayPoint SHOP",
    "/docking/dock dock",
]


def intro(engaged: bool | None = True) -> list[str]:
    return ["start_introduction True", f"ask_tour {engaged}"]


def content(poi: str, waypoint: str | None = None, parts: str = "a") -> list[str]:
    return [*(f"start_poi {poi} {waypoint or poi} {p}" for p in parts), f"finish_poi {poi}"]


def test_morning_tour_takes_the_a_variants_and_ends_docked():
    t = tour({"start_time": "2026-06-01T10:30:00+02:00"})
    assert t.outcome.code == 0, t.outcome.reason
    assert t.executive.core.stray_answers == 0  # the "yes" came while it was asked for
    assert t.ros_commands() == [
        "/docking/dock undock",
        "/GotoWayPoint POI0",
        *RECRUIT_7,
        "/GotoWayPoint POI1a",
        *FACES,
        "/GotoWayPoint POI2a",
        *FACES,
        *AFTER_RECRUIT,
    ]
    assert t.frontend_commands(*STORY) == [
        "tour started",
        *intro(),
        *content("POI1", "POI1a", "ab"),
        *content("POI2", "POI2a", "ab"),
        *content("POI3"),
        *content("POI4"),
        *content("POI5"),
        *content("END"),
        "tour ended",
    ]
    assert t.sim.world.docking.state == "docked"


def test_afternoon_tour_takes_the_b_variants():
    t = tour({"start_time": "2026-06-01T15:10:00+02:00"})
    assert t.outcome.code == 0, t.outcome.reason
    assert t.summary.visited[:3] == ["POI0", "POI1b", "POI2b"]
    assert t.frontend_commands("start_poi")[:4] == [
        "start_poi POI1 POI1b a",
        "start_poi POI1 POI1b b",
        "start_poi POI2 POI2b a",
        "start_poi POI2 POI2b b",
    ]


def test_rejected_approach_seeks_again_and_is_then_accepted():
    t = tour(
        {
            "visitors": [
                {
                    "id": 7,
                    "position": [103.0, 36.0],
                    "facing": True,
                    "approach": ["aborted", "succeeded"],
                }
            ]
        }
    )
    assert t.outcome.code == 0, t.outcome.reason
    assert t.ros_commands()[:5] == [
        "/docking/dock undock",
        "/GotoWayPoint POI0",
        "/ApproachPeopleFar 7",
        "/ApproachPeopleFar 7",
        "/ICL_command start",
    ]
    assert t.summary.recruited == [7]


def test_user_negative_then_a_second_visitor_who_says_yes():
    t = tour(
        {
            "visitors": [
                {"id": 7, "position": [103.0, 36.0], "facing": True, "answer": "negative"},
                {"id": 8, "position": [105.5, 35.0], "facing": True, "appear_at": 60},
            ]
        }
    )
    assert t.outcome.code == 0, t.outcome.reason
    assert t.ros_commands()[:9] == [
        "/docking/dock undock",
        "/GotoWayPoint POI0",
        *RECRUIT_7,
        "/ApproachPeopleFar 8",
        *FACES,
        "/GotoWayPoint POI1a",
    ]
    assert t.frontend_commands(*STORY)[:5] == ["tour started", *intro(), *intro()]
    assert t.summary.recruited == [8]


def test_a_nearer_visitor_who_is_not_facing_is_ignored():
    t = tour(
        {
            "visitors": [
                {"id": 5, "position": [104.0, 34.0], "facing": False},
                {"id": 7, "position": [103.0, 38.0], "facing": True},
            ]
        }
    )
    assert t.outcome.code == 0, t.outcome.reason
    assert [c for c in t.ros_commands() if c.startswith("/Approach")] == ["/ApproachPeopleFar 7"]


def test_visitor_wandering_off_before_poi2_sends_the_robot_back_to_recruit():
    t = tour(
        {
            "visitors": [
                {
                    "id": 7,
                    "position": [103.0, 36.0],
                    "facing": True,
                    "wander_off": {"heading_to": "POI2"},
                },
                {"id": 9, "position": [102.0, 35.0], "facing": True, "appear_at": 200},
            ]
        }
    )
    assert t.outcome.code == 0, t.outcome.reason
    assert t.ros_commands()[:13] == [
        "/docking/dock undock",
        "/GotoWayPoint POI0",
        *RECRUIT_7,
        "/GotoWayPoint POI1a",
        *FACES,
        "/GotoWayPoint POI2a",  # nobody follows on arrival: no content
        "/GotoWayPoint POI0",
        "/ApproachPeopleFar 9",
        *FACES,
    ]
    starts = [c for c in t.frontend_commands("start_poi") if c.endswith(" a")]
    assert starts[:3] == [
        "start_poi POI1 POI1a a",
        "start_poi POI1 POI1a a",
        "start_poi POI2 POI2a a",
    ]  # the new visitor gets the tour from POI1
    assert t.summary.recruited == [7, 9]


def test_four_visitors_lost_in_a_row_give_the_tour_up_with_its_reason_and_dock():
    # One visitor who says yes and never follows: lost on arrival at POI1 each time.
    t = tour({"visitors": [{"id": 7, "position": [103.0, 36.0], "facing": True, "follow": False}]})
    assert (t.outcome.code, t.outcome.reason) == (1, "tour aborted: no visitor could be guided")
    assert t.frontend_commands("tour")[-1] == "tour aborted no visitor could be guided"
    commands = t.ros_commands()
    assert commands.count("/ApproachPeopleFar 7") == 4  # the Retry's four tries
    assert commands[-2:] == ["/GotoWayPoint SHOP", "/docking/dock dock"]


def test_navigation_failure_is_retried_then_the_stop_is_skipped():
    t = tour(
        {
            "navigation": {
                "failures": [
                    {"poi": "POI1", "times": 1, "result": "aborted", "after": 5},
                    {"poi": "POI3", "times": 3, "result": "failed", "after": 5},
                ]
            }
        }
    )
    assert t.outcome.code == 0, t.outcome.reason
    gotos = [c for c in t.ros_commands() if c.startswith("/GotoWayPoint")]
    assert gotos == [
        "/GotoWayPoint POI0",
        "/GotoWayPoint POI1a",
        "/GotoWayPoint POI1a",
        "/GotoWayPoint POI2a",
        "/GotoWayPoint POI3",
        "/GotoWayPoint POI3",
        "/GotoWayPoint POI3",
        "/GotoWayPoint POI4",
        "/GotoWayPoint POI5",
        "/GotoWayPoint TEMP",
        "/GotoWayPoint END",
        "/GotoWayPoint SHOP",
    ]
    starts = [c.split()[1] for c in t.frontend_commands("start_poi") if c.endswith(" a")]
    assert starts == ["POI1", "POI2", "POI4", "POI5", "END"]  # POI3 skipped
