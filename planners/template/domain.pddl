; __TASK__: fetch an item and bring it to a place.  Written by 'tasker new'; edit freely.
; Standard PDDL: any classical planner reads it.  tasker fills `connected` and `travel-time`
; from the robot's motion model (OMPL paths in the world) when it builds a problem.
(define (domain __TASK__)
  (:requirements :strips :typing :negative-preconditions :action-costs)
  (:types locatable place - object
          robot item - locatable)
  (:predicates
    (at ?x - locatable ?p - place)
    (connected ?from ?to - place)
    (holding ?r - robot ?i - item)
    (hand_empty ?r - robot))
  (:functions
    (travel-time ?from ?to - place) - number
    (total-cost) - number)

  (:action navigate
    :parameters (?r - robot ?from ?to - place)
    :precondition (and (at ?r ?from) (connected ?from ?to))
    :effect (and (not (at ?r ?from)) (at ?r ?to)
                 (increase (total-cost) (travel-time ?from ?to))))

  (:action pick
    :parameters (?r - robot ?i - item ?p - place)
    :precondition (and (at ?r ?p) (at ?i ?p) (hand_empty ?r))
    :effect (and (holding ?r ?i) (not (hand_empty ?r)) (not (at ?i ?p))
                 (increase (total-cost) 5)))

  (:action put_down
    :parameters (?r - robot ?i - item ?p - place)
    :precondition (and (at ?r ?p) (holding ?r ?i))
    :effect (and (at ?i ?p) (hand_empty ?r) (not (holding ?r ?i))
                 (increase (total-cost) 5)))
)
