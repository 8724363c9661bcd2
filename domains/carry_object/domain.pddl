; carry_object: carry a fragile object to a place, through doors the robot must open
; with an empty hand. Objects may only be put down on a clear surface (`clear` is the world's:
; no movable object rests there).
(define (domain carry_object)
  (:requirements :strips :typing :negative-preconditions :action-costs)
  (:types locatable place door - object
          robot item - locatable)
  (:predicates
    (at ?x - locatable ?p - place)
    (connected ?from ?to - place)
    (free_passage ?from ?to - place)
    (door_between ?d - door ?from ?to - place)
    (door_at ?d - door ?p - place)
    (open ?d - door)
    (holding ?r - robot ?i - item)
    (hand_empty ?r - robot)
    (surface ?p - place)
    (clear ?p - place))
  (:functions
    (travel-time ?from ?to - place) - number
    (total-cost) - number)

  (:action navigate
    :parameters (?r - robot ?from ?to - place)
    :precondition (and (at ?r ?from) (connected ?from ?to) (free_passage ?from ?to))
    :effect (and (not (at ?r ?from)) (at ?r ?to)
                 (increase (total-cost) (travel-time ?from ?to))))

  (:action navigate_through
    :parameters (?r - robot ?d - door ?from ?to - place)
    :precondition (and (at ?r ?from) (connected ?from ?to) (door_between ?d ?from ?to) (open ?d))
    :effect (and (not (at ?r ?from)) (at ?r ?to)
                 (increase (total-cost) (travel-time ?from ?to))))

  (:action open_door
    :parameters (?r - robot ?d - door ?p - place)
    :precondition (and (at ?r ?p) (door_at ?d ?p) (hand_empty ?r) (not (open ?d)))
    :effect (and (open ?d) (increase (total-cost) 6)))

  (:action close_door
    :parameters (?r - robot ?d - door ?p - place)
    :precondition (and (at ?r ?p) (door_at ?d ?p) (hand_empty ?r) (open ?d))
    :effect (and (not (open ?d)) (increase (total-cost) 6)))

  (:action pick
    :parameters (?r - robot ?i - item ?p - place)
    :precondition (and (at ?r ?p) (at ?i ?p) (hand_empty ?r))
    :effect (and (holding ?r ?i) (not (hand_empty ?r)) (not (at ?i ?p)) (clear ?p) (increase (total-cost) 8)))

  (:action place
    :parameters (?r - robot ?i - item ?p - place)
    :precondition (and (at ?r ?p) (holding ?r ?i) (surface ?p) (clear ?p))
    :effect (and (at ?i ?p) (not (clear ?p)) (hand_empty ?r) (not (holding ?r ?i)) (increase (total-cost) 8)))
)
