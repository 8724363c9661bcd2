; human_fell: reach a person who fell, check that they are conscious, call for help.
(define (domain human_fell)
  (:requirements :strips :typing :negative-preconditions :action-costs)
  (:types locatable place - object
          robot person - locatable)
  (:predicates
    (target ?h - person)
    (at ?x - locatable ?p - place)
    (connected ?from ?to - place)
    (fallen ?h - person)
    (checked ?h - person)
    (help_called ?h - person)
    (reassured ?h - person))
  (:functions
    (travel-time ?from ?to - place) - number
    (total-cost) - number)

  (:action approach
    :parameters (?r - robot ?h - person ?from ?to - place)
    :precondition (and (target ?h) (at ?r ?from) (at ?h ?to) (connected ?from ?to))
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
)
