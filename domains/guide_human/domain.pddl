; guide_human: approach a person, greet, ask them to follow, guide them, say goodbye.
; Costs are expected durations in seconds; travel-time comes from the motion model.
; The robot remembers a door it opened (opened_by_robot) until it closes it: its suspension tree
; closes such a door, never one it found open.
; A door found closed on the way is opened with an empty hand (as in carry_object): the robot
; goes to a door's place (approach_door, or guide), opens it and passes it alone
; (approach_through) or with the person (guide_through).
(define (domain guide_human)
  (:requirements :strips :typing :negative-preconditions :action-costs)
  (:types locatable place door - object
          robot person - locatable)
  (:predicates
    (target ?h - person)
    (at ?x - locatable ?p - place)
    (connected ?from ?to - place)
    (free_passage ?from ?to - place)
    (door_between ?d - door ?from ?to - place)
    (door_at ?d - door ?p - place)
    (open ?d - door)
    (opened_by_robot ?d - door)
    (hand_empty ?r - robot)
    (greeted ?h - person)
    (following ?h - person)
    (told_to_wait ?h - person)
    (apology_due ?h - person))
  (:functions
    (travel-time ?from ?to - place) - number
    (total-cost) - number)

  (:action approach
    :parameters (?r - robot ?h - person ?from ?to - place)
    :precondition (and (target ?h) (at ?r ?from) (at ?h ?to) (connected ?from ?to) (free_passage ?from ?to) (not (following ?h)))
    :effect (and (not (at ?r ?from)) (at ?r ?to)
                 (increase (total-cost) (travel-time ?from ?to))))

  (:action greet
    :parameters (?r - robot ?h - person ?p - place)
    :precondition (and (at ?r ?p) (at ?h ?p) (not (greeted ?h)) (not (apology_due ?h)))
    :effect (and (greeted ?h) (increase (total-cost) 3)))

  (:action greet_and_apologise
    :parameters (?r - robot ?h - person ?p - place)
    :precondition (and (at ?r ?p) (at ?h ?p) (apology_due ?h))
    :effect (and (greeted ?h) (not (apology_due ?h)) (increase (total-cost) 6)))

  (:action ask_to_follow
    :parameters (?r - robot ?h - person ?p - place)
    :precondition (and (at ?r ?p) (at ?h ?p) (greeted ?h) (not (apology_due ?h)) (not (following ?h)))
    :effect (and (following ?h) (not (told_to_wait ?h)) (increase (total-cost) 2)))

  (:action guide
    :parameters (?r - robot ?h - person ?from ?to - place)
    :precondition (and (target ?h) (at ?r ?from) (at ?h ?from) (following ?h) (connected ?from ?to) (free_passage ?from ?to))
    :effect (and (not (at ?r ?from)) (at ?r ?to) (not (at ?h ?from)) (at ?h ?to)
                 (increase (total-cost) (travel-time ?from ?to))))

  (:action say_goodbye
    :parameters (?r - robot ?h - person ?p - place)
    :precondition (and (at ?r ?p) (at ?h ?p) (following ?h))
    :effect (and (not (following ?h)) (increase (total-cost) 2)))

  (:action ask_to_wait
    :parameters (?r - robot ?h - person ?p - place)
    :precondition (and (at ?r ?p) (at ?h ?p) (greeted ?h))
    :effect (and (told_to_wait ?h) (not (following ?h)) (increase (total-cost) 3)))

  ; to a closed door's place, to open it (not a way of moving about: that is approach's)
  (:action approach_door
    :parameters (?r - robot ?d - door ?from ?to - place)
    :precondition (and (at ?r ?from) (connected ?from ?to) (free_passage ?from ?to) (door_at ?d ?to) (not (open ?d)))
    :effect (and (not (at ?r ?from)) (at ?r ?to)
                 (increase (total-cost) (travel-time ?from ?to))))

  (:action approach_through
    :parameters (?r - robot ?h - person ?d - door ?from ?to - place)
    :precondition (and (target ?h) (at ?r ?from) (connected ?from ?to) (door_between ?d ?from ?to) (open ?d) (not (following ?h)))
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

  (:action guide_through
    :parameters (?r - robot ?h - person ?d - door ?from ?to - place)
    :precondition (and (target ?h) (at ?r ?from) (at ?h ?from) (following ?h) (connected ?from ?to)
                       (door_between ?d ?from ?to) (open ?d))
    :effect (and (not (at ?r ?from)) (at ?r ?to) (not (at ?h ?from)) (at ?h ?to)
                 (increase (total-cost) (travel-time ?from ?to))))
)
