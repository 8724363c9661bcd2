; water_plants: fetch the watering can, fill it at the tap, water the plants.
; The tap is a device of the world: it runs until the robot turns it off.  The can goes down only
; on a clear surface: `surface` is a fact of the world file, `clear` the world's own (no movable
; object rests there).  Picking the can up clears its place, as in the bundled domains: a plan
; assumes one thing a spot (the world, read afresh at each planning call, says otherwise when
; something else stands there too).
(define (domain water_plants)
  (:requirements :strips :typing :negative-preconditions :action-costs)
  (:types locatable place - object
          robot can tap plant - locatable)
  (:predicates
    (at ?x - locatable ?p - place)
    (connected ?from ?to - place)
    (holding ?r - robot ?c - can)
    (hand_empty ?r - robot)
    (surface ?p - place)
    (clear ?p - place)
    (tap_on ?t - tap)
    (full ?c - can)
    (watered ?pl - plant))
  (:functions
    (travel-time ?from ?to - place) - number
    (total-cost) - number)

  (:action navigate
    :parameters (?r - robot ?from ?to - place)
    :precondition (and (at ?r ?from) (connected ?from ?to))
    :effect (and (not (at ?r ?from)) (at ?r ?to)
                 (increase (total-cost) (travel-time ?from ?to))))

  (:action pick
    :parameters (?r - robot ?c - can ?p - place)
    :precondition (and (at ?r ?p) (at ?c ?p) (hand_empty ?r))
    :effect (and (holding ?r ?c) (not (hand_empty ?r)) (not (at ?c ?p)) (clear ?p)
                 (increase (total-cost) 6)))

  (:action put_down
    :parameters (?r - robot ?c - can ?p - place)
    :precondition (and (at ?r ?p) (holding ?r ?c) (surface ?p) (clear ?p))
    :effect (and (at ?c ?p) (not (clear ?p)) (hand_empty ?r) (not (holding ?r ?c))
                 (increase (total-cost) 5)))

  (:action turn_on
    :parameters (?r - robot ?t - tap ?p - place)
    :precondition (and (at ?r ?p) (at ?t ?p) (not (tap_on ?t)))
    :effect (and (tap_on ?t) (increase (total-cost) 2)))

  (:action fill
    :parameters (?r - robot ?c - can ?t - tap ?p - place)
    :precondition (and (at ?r ?p) (at ?t ?p) (tap_on ?t) (holding ?r ?c) (not (full ?c)))
    :effect (and (full ?c) (increase (total-cost) 20)))

  (:action turn_off
    :parameters (?r - robot ?t - tap ?p - place)
    :precondition (and (at ?r ?p) (at ?t ?p) (tap_on ?t))
    :effect (and (not (tap_on ?t)) (increase (total-cost) 2)))

  (:action water
    :parameters (?r - robot ?c - can ?pl - plant ?p - place)
    :precondition (and (at ?r ?p) (at ?pl ?p) (holding ?r ?c) (full ?c))
    :effect (and (watered ?pl) (not (full ?c)) (increase (total-cost) 15)))
)
