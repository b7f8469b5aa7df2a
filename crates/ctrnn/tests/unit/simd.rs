use ctrnn::simd::*;

#[test]
fn names_round_trip_and_unknown_names_are_errors() {
    for k in Kernel::ALL {
        assert_eq!(k.name().parse::<Kernel>().unwrap(), k);
    }
    let err = "avx513".parse::<Kernel>().unwrap_err().to_string();
    assert!(err.contains("avx513") && err.contains("portable"), "{err}");
}

#[test]
fn the_best_kernel_is_supported_and_portable_always_is() {
    assert!(best().is_supported());
    assert!(supported().contains(&Kernel::Portable));
    assert!(supported().contains(&best()));
}

#[test]
fn an_unsupported_kernel_cannot_be_set() {
    for k in Kernel::ALL {
        assert_eq!(set_kernel(k).is_ok(), k.is_supported(), "{k}");
    }
    set_kernel(best()).unwrap();
}
