; fetch_t: fetch an item and bring it to a place.  Written by 'tasker new --temporal'; edit freely.
; Temporal PDDL 2.1 (durative actions), as PlanSys2 and ROSPlan write it: LPG, Aries and Kairos
; plan it through unified-planning, and every plan is validated (docs/planners.md).  tasker fills
; `connected` and `travel-time` from the robot's motion model when it builds a problem.  One robot
; does one thing at a time: a plan with two of its actions overlapping is refused.
(define (domain fetch_t)
  (:requirements :strips :typing :durative-actions :fluents :negative-preconditions)
  (:types locatable place - object
          robot item - locatable)
  (:predicates
    (at ?x - locatable ?p - place)
    (connected ?from ?to - place)
    (holding ?r - robot ?i - item)
    (hand_empty ?r - robot))
  (:functions
    (travel-time ?from ?to - place) - number)

  ; its stage is timed by the motion model (task.toml: travel = ["?from", "?to"])
  (:durative-action navigate
    :parameters (?r - robot ?from ?to - place)
    :duration (= ?duration (travel-time ?from ?to))
    :condition (and (at start (at ?r ?from)) (at start (connected ?from ?to)))
    :effect (and (at start (not (at ?r ?from))) (at end (at ?r ?to))))

  ; a fixed :duration is the stage's duration (unless task.toml gives one)
  (:durative-action pick
    :parameters (?r - robot ?i - item ?p - place)
    :duration (= ?duration 5)
    :condition (and (at start (at ?i ?p)) (at start (hand_empty ?r)) (over all (at ?r ?p)))
    :effect (and (at start (not (hand_empty ?r))) (at start (not (at ?i ?p))) (at end (holding ?r ?i))))

  (:durative-action put_down
    :parameters (?r - robot ?i - item ?p - place)
    :duration (= ?duration 5)
    :condition (and (at start (holding ?r ?i)) (over all (at ?r ?p)))
    :effect (and (at start (not (holding ?r ?i))) (at end (at ?i ?p)) (at end (hand_empty ?r))))
)
