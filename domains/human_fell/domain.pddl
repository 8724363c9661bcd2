; human_fell: reach a person who fell, check that they are conscious, call for help.
; The robot remembers a door it opened (opened_by_robot) until it closes it: its suspension tree
; closes such a door, never one it found open.
; A door found closed on the way is opened with an empty hand (as in carry_object): the robot
; goes to a door's place (approach_door), opens it and passes it (approach_through).
(define (domain human_fell)
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
    (fallen ?h - person)
    (checked ?h - person)
    (help_called ?h - person)
    (reassured ?h - person))
  (:functions
    (travel-time ?from ?to - place) - number
    (total-cost) - number)

  (:action approach
    :parameters (?r - robot ?h - person ?from ?to - place)
    :precondition (and (target ?h) (at ?r ?from) (at ?h ?to) (connected ?from ?to) (free_passage ?from ?to))
    :effect (and (not (at ?r ?from)) (at ?r ?to)
                 (increase (total-cost) (travel-time ?from ?to))))

  (:action check_consciousness
    :parameters (?r - robot ?h - person ?p - place)
    :precondition (and (at ?r ?p) (at ?h ?p) (fallen ?h))
    :effect (and (checked ?h) (increase (total-cost) 10)))

  (:action call_help
    :parameters (?r - robot ?h - person ?p - place)
    :precondition (and (at ?r ?p) (at ?h ?p))
    :effect (and (help_called ?h) (increase (total-cost) 8)))

  (:action reassure
    :parameters (?r - robot ?h - person ?p - place)
    :precondition (and (at ?r ?p) (at ?h ?p))
    :effect (and (reassured ?h) (increase (total-cost) 4)))

  ; to a closed door's place, to open it (not a way of moving about: that is approach's)
  (:action approach_door
    :parameters (?r - robot ?d - door ?from ?to - place)
    :precondition (and (at ?r ?from) (connected ?from ?to) (free_passage ?from ?to) (door_at ?d ?to) (not (open ?d)))
    :effect (and (not (at ?r ?from)) (at ?r ?to)
                 (increase (total-cost) (travel-time ?from ?to))))

  (:action approach_through
    :parameters (?r - robot ?h - person ?d - door ?from ?to - place)
    :precondition (and (target ?h) (at ?r ?from) (connected ?from ?to) (door_between ?d ?from ?to) (open ?d))
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
