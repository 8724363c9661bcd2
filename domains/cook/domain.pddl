; cook: put a pan on the cooker, cook, turn the cooker off and put the hot pan down.
; The robot remembers a door it opened (opened_by_robot) until it closes it: its suspension tree
; closes such a door, never one it found open.
; A door found closed on the way is opened with an empty hand (as in carry_object).
; The pan rests at a place (at ?k ?p), is held, or stands on the cooker (on_cooker, not at a
; place). It goes down only on a clear, heat-proof spot: `clear` is the world's (no movable
; object rests there), `heat_proof` a fact of the world file.
(define (domain cook)
  (:requirements :strips :typing :negative-preconditions :action-costs)
  (:types locatable place door - object
          robot pan cooker - locatable)
  (:predicates
    (at ?x - locatable ?p - place)
    (connected ?from ?to - place)
    (free_passage ?from ?to - place)
    (door_between ?d - door ?from ?to - place)
    (door_at ?d - door ?p - place)
    (open ?d - door)
    (opened_by_robot ?d - door)
    (holding ?r - robot ?k - pan)
    (hand_empty ?r - robot)
    (heat_proof ?p - place)
    (clear ?p - place)
    (on_cooker ?k - pan ?c - cooker)
    (cooker_on ?c - cooker)
    (cooked ?k - pan))
  (:functions
    (travel-time ?from ?to - place) - number
    (total-cost) - number)

  (:action navigate
    :parameters (?r - robot ?from ?to - place)
    :precondition (and (at ?r ?from) (connected ?from ?to) (free_passage ?from ?to))
    :effect (and (not (at ?r ?from)) (at ?r ?to)
                 (increase (total-cost) (travel-time ?from ?to))))

  (:action pick_pan
    :parameters (?r - robot ?k - pan ?p - place)
    :precondition (and (at ?r ?p) (at ?k ?p) (hand_empty ?r))
    :effect (and (holding ?r ?k) (not (hand_empty ?r)) (not (at ?k ?p)) (clear ?p)
                 (increase (total-cost) 6)))

  (:action put_on_cooker
    :parameters (?r - robot ?k - pan ?c - cooker ?p - place)
    :precondition (and (at ?r ?p) (at ?c ?p) (holding ?r ?k))
    :effect (and (on_cooker ?k ?c) (hand_empty ?r) (not (holding ?r ?k))
                 (increase (total-cost) 5)))

  (:action take_off_cooker
    :parameters (?r - robot ?k - pan ?c - cooker ?p - place)
    :precondition (and (at ?r ?p) (on_cooker ?k ?c) (at ?c ?p) (hand_empty ?r))
    :effect (and (holding ?r ?k) (not (hand_empty ?r)) (not (on_cooker ?k ?c))
                 (increase (total-cost) 5)))

  (:action put_down
    :parameters (?r - robot ?k - pan ?p - place)
    :precondition (and (at ?r ?p) (holding ?r ?k) (heat_proof ?p) (clear ?p))
    :effect (and (at ?k ?p) (not (clear ?p)) (hand_empty ?r) (not (holding ?r ?k))
                 (increase (total-cost) 5)))

  (:action turn_on
    :parameters (?r - robot ?c - cooker ?p - place)
    :precondition (and (at ?r ?p) (at ?c ?p) (not (cooker_on ?c)))
    :effect (and (cooker_on ?c) (increase (total-cost) 2)))

  (:action turn_off
    :parameters (?r - robot ?c - cooker ?p - place)
    :precondition (and (at ?r ?p) (at ?c ?p) (cooker_on ?c))
    :effect (and (not (cooker_on ?c)) (increase (total-cost) 2)))

  (:action cook_food
    :parameters (?r - robot ?k - pan ?c - cooker ?p - place)
    :precondition (and (at ?r ?p) (at ?c ?p) (on_cooker ?k ?c) (cooker_on ?c) (not (cooked ?k)))
    :effect (and (cooked ?k) (increase (total-cost) 120)))

  (:action navigate_through
    :parameters (?r - robot ?d - door ?from ?to - place)
    :precondition (and (at ?r ?from) (connected ?from ?to) (door_between ?d ?from ?to) (open ?d))
    :effect (and (not (at ?r ?from)) (at ?r ?to)
                 (increase (total-cost) (travel-time ?from ?to))))

  (:action open_door
    :parameters (?r - robot ?d - door ?p - place)
    :precondition (and (at ?r ?p) (door_at ?d ?p) (hand_empty ?r) (not (open ?d)))
    :effect (and (open ?d) (opened_by_robot ?d) (increase (total-cost) 6)))

  (:action close_door
    :parameters (?r - robot ?d - door ?p - place)
    :precondition (and (at ?r ?p) (door_at ?d ?p) (hand_empty ?r) (open ?d))
    :effect (and (not (open ?d)) (not (opened_by_robot ?d)) (increase (total-cost) 6)))
)
