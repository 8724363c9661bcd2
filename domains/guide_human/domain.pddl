; guide_human: approach a person, greet, ask them to follow, guide them, say goodbye.
; Costs are expected durations in seconds; travel-time comes from the motion model.
(define (domain guide_human)
  (:requirements :strips :typing :negative-preconditions :action-costs)
  (:types locatable place - object
          robot person - locatable)
  (:predicates
    (target ?h - person)
    (at ?x - locatable ?p - place)
    (connected ?from ?to - place)
    (greeted ?h - person)
    (following ?h - person)
    (told_to_wait ?h - person)
    (apology_due ?h - person))
  (:functions
    (travel-time ?from ?to - place) - number
    (total-cost) - number)

  (:action approach
    :parameters (?r - robot ?h - person ?from ?to - place)
    :precondition (and (target ?h) (at ?r ?from) (at ?h ?to) (connected ?from ?to) (not (following ?h)))
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
    :precondition (and (target ?h) (at ?r ?from) (at ?h ?from) (following ?h) (connected ?from ?to))
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
)
