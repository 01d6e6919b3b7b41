//! Criterion benchmarks of overhead processing on a rendered 640×480 overhead-game frame
//! (4–8 robots with markers, the ball, distortion): the whole overhead pipeline
//! (classification, blobs, ball and markers) and the recogniser alone, through the frame's
//! true camera, with a table learnt from the renderer's labels of other frames.

use std::hint::black_box;

use criterion::{Criterion, criterion_group, criterion_main};
use eotn::blobs::{BlobSet, Connectivity};
use eotn::classify::ClassifiedImage;
use eotn::lut::learn::{LearnParams, TableBuilder};
use eotn::model::truth::GroundTruth;
use eotn::overhead::{OverheadParams, OverheadPipeline, recognise_overhead};
use eotn::sim::{Scenario, ScenarioKind, Simulator};

fn overhead(c: &mut Criterion) {
    let sim = Simulator::new(Scenario::new(ScenarioKind::OverheadGame, 1));
    let mut builder = TableBuilder::new(7).expect("7 bits");
    for index in [30, 120] {
        let f = sim.frame(index).expect("renders");
        builder.add_frame(&f.frame, &f.labels).expect("labels fit");
    }
    let table = builder.build(&LearnParams::default());
    let f = sim.frame(60).expect("renders");
    let GroundTruth::Overhead(truth) = &f.ground_truth else {
        panic!("overhead view expected");
    };
    let params = OverheadParams::default();
    let mut pipeline = OverheadPipeline::new(table.clone(), truth.camera, params);
    c.bench_function("overhead_process_640x480", |b| {
        b.iter(|| black_box(pipeline.process(black_box(&f.frame)).robots.len()));
    });
    let classified = ClassifiedImage::from_frame(&f.frame, &table);
    let blobs = BlobSet::from_image(&classified, Connectivity::Eight);
    c.bench_function("overhead_recognise_640x480", |b| {
        b.iter(|| {
            black_box(
                recognise_overhead(&classified, &blobs, &truth.camera, &params)
                    .robots
                    .len(),
            )
        });
    });
}

criterion_group!(benches, overhead);
criterion_main!(benches);
