; hot_pot: carry a hot pot from the stove to a table.  A hot pot goes down only on a clear,
; heat-proof spot: `heat_proof` is a fact of the world file, `clear` the world's own (no movable
; object rests there).  Picking the pot up clears its place (a plan assumes one thing a spot;
; the world, read afresh at every planning call, says when something else stands there too).
; A door found closed on the way is opened with an empty hand (docs/domains.md, "A door the
; task may find closed"): with the pot in hand the robot cannot open one.
(define (domain hot_pot)
  (:requirements :strips :typing :negative-preconditions :action-costs)
  (:types locatable place door - object
          robot pot - locatable)
  (:predicates
    (at ?x - locatable ?p - place)
    (connected ?from ?to - place)
    (free_passage ?from ?to - place)
    (door_between ?d - door ?from ?to - place)
    (door_at ?d - door ?p - place)
    (open ?d - door)
    (holding ?r - robot ?x - pot)
    (hand_empty ?r - robot)
    (heat_proof ?p - place)
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

  (:action pick_pot
    :parameters (?r - robot ?x - pot ?p - place)
    :precondition (and (at ?r ?p) (at ?x ?p) (hand_empty ?r))
    :effect (and (holding ?r ?x) (not (hand_empty ?r)) (not (at ?x ?p)) (clear ?p)
                 (increase (total-cost) 5)))

  (:action put_pot
    :parameters (?r - robot ?x - pot ?p - place)
    :precondition (and (at ?r ?p) (holding ?r ?x) (heat_proof ?p) (clear ?p))
    :effect (and (at ?x ?p) (not (clear ?p)) (hand_empty ?r) (not (holding ?r ?x))
                 (increase (total-cost) 5)))
)
