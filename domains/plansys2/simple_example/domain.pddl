; PlanSys2's simple example (ros2_planning_system_examples/plansys2_simple_example/pddl/simple_example.pddl,
; Apache-2.0, Intelligent Robotics Lab) as a tasker task folder.  Its actions, conditions and effects are
; PlanSys2's; what changed is what tasker's world says (docs/planners.md, "From PlanSys2 to tasker"):
;   room -> place, robot_at -> at    the places and the robot's place are the world's (grounded in physics);
;   move's (= ?duration 5)            -> (travel-time ?r1 ?r2): tasker times a drive with the motion model,
;                                        and fills travel-time and connected for every problem;
;   askcharge                          gets the same travel time (PlanSys2's robot is taken to the charger);
;   the empty (:functions ) block      now declares travel-time.
(define (domain plansys2_simple)
(:requirements :strips :typing :adl :fluents :durative-actions)

(:types
robot
place
)

(:predicates
(at ?r - robot ?ro - place)
(connected ?ro1 ?ro2 - place)
(battery_full ?r - robot)
(battery_low ?r - robot)
(charging_point_at ?ro - place)
)

(:functions
(travel-time ?from ?to - place) - number
)

(:durative-action move
    :parameters (?r - robot ?r1 ?r2 - place)
    :duration ( = ?duration (travel-time ?r1 ?r2))
    :condition (and
        (at start(connected ?r1 ?r2))
        (at start(at ?r ?r1))
        (over all(battery_full ?r))
        )
    :effect (and
        (at start(not(at ?r ?r1)))
        (at end(at ?r ?r2))
    )
)

(:durative-action askcharge
    :parameters (?r - robot ?r1 ?r2 - place)
    :duration ( = ?duration (travel-time ?r1 ?r2))
    :condition (and
        (at start(at ?r ?r1))
        (at start(charging_point_at ?r2))
       )
    :effect (and
        (at start(not(at ?r ?r1)))
        (at end(at ?r ?r2))
    )
)

(:durative-action charge
    :parameters (?r - robot ?ro - place)
    :duration ( = ?duration 5)
    :condition (and
        (at start(at ?r ?ro))
        (at start(charging_point_at ?ro))
    )
    :effect (and
         (at end(not(battery_low ?r)))
         (at end(battery_full ?r))
    )
)
)
