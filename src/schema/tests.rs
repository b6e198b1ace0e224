use super::*;

#[test]
fn visit_names_exactly_the_schema_in_its_order() {
    let s = Scenario::<2>::preset(Preset::Robot, Law::StateFeedback);
    let mut seen = alloc::vec::Vec::new();
    s.visit(|name, _| seen.push(name));
    let table: alloc::vec::Vec<_> = PARAMS.iter().map(|p| p.name).collect();
    assert_eq!(seen, table);
}

#[test]
fn every_value_round_trips_through_set_and_visit() {
    for preset in Preset::ALL {
        let s = Scenario::<2>::preset(preset, Law::OutputFeedback);
        let mut copy = Scenario::<2>::preset(Preset::Paper, Law::OutputFeedback);
        s.visit(|name, v| copy.set(name, v).unwrap());
        assert_eq!(copy, s, "{preset:?}");
        // The defaults the table declares are the values visited.
        s.visit(|name, v| {
            let d = param(name).unwrap().default_in(preset);
            match (d, v) {
                (Value::Real(x), Value::Vec(y)) => assert!(y.iter().all(|y| *y == x), "{name}"),
                (d, v) => assert_eq!(d, v, "{name}"),
            }
        });
    }
}

#[test]
fn presets_apply_for_every_size() {
    fn check<const N: usize>() {
        for preset in Preset::ALL {
            let s = Scenario::<N>::preset(preset, Law::StateFeedback);
            assert_eq!(s.config.kp, Vector::<N>::from_element(10.0));
        }
    }
    check::<1>();
    check::<2>();
    check::<3>();
    check::<5>();
    check::<7>();
}

#[test]
fn every_choice_name_maps_to_a_distinct_variant() {
    let mut s = Scenario::<2>::preset(Preset::Paper, Law::Pd);
    for p in PARAMS {
        if let Kind::Choice(names) = p.kind {
            for name in names {
                s.set(p.name, Value::Str(name)).unwrap();
                s.visit(|n, v| {
                    if n == p.name {
                        assert_eq!(v, Value::Str(name));
                    }
                });
            }
            let e = s.set(p.name, Value::Str("nonsense")).unwrap_err();
            assert!(e.to_string().contains("not one of its choices"), "{e}");
        }
    }
}

#[test]
fn bad_names_and_kinds_are_errors() {
    let mut s = Scenario::<2>::preset(Preset::Paper, Law::Pd);
    assert!(s.set("Kpp", Value::Real(1.0)).is_err());
    assert!(s.set("Kp", Value::Str("x")).is_err());
    assert!(s.set("Kp", Value::Vec(&[1.0, 2.0, 3.0])).is_err());
    let e = s.set("substeps", Value::Int(-1)).unwrap_err();
    assert!(e.to_string().contains("1 ≤ substeps ≤ 10 000"), "{e}");
    s.set("weight_bound", Value::Vec(&[1.0, 2.0, 3.0])).unwrap();
    assert_eq!(s.config.weight_bound, WeightBound::Fixed([1.0, 2.0, 3.0]));
    s.set("weight_bound", Value::Real(2.0)).unwrap();
    assert_eq!(s.config.weight_bound, WeightBound::Fixed([2.0; 3]));
}
